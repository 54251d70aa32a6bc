"""How the cell works: the welding process, perception, the locator, the re-scan, and the faults a simulation
plays. Lengths in metres (``_m``) or millimetres (``_mm``), angles in degrees (``_deg``)."""

from __future__ import annotations

import dataclasses
import difflib
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, ValidationError, field_validator, model_validator

from cell.config import (
    CONFIDENCE_THRESHOLD,
    BeadStyle,
    CoverageOptions,
    GateOptions,
    HealthOptions,
    KrlOptions,
    PlanOptions,
    RescanOptions,
    ScreenOptions,
    SymmetryOptions,
)
from cell.config.rescan import (
    BOUND_SIGMAS,
    END_TOLERANCE_MM,
    SANE_BOUND_SIGMAS,
    SANE_END_TOLERANCE_MM,
    SANE_WELD_TOLERANCE_MM,
    WELD_TOLERANCE_MM,
)
from cell.geometry import FloatArray, pose_from_xyz_rpy
from cell.scenario.base import Model, Pos, Vec3
from cell.scenario.cell_specs import Deviation, PoseSpec, WorkspaceSpec
from cell.scenario.locator_specs import LOCATOR_SPECS, spec_method
from cell.scenario.realism_specs import BowSpec, GapsSpec, SpecularDropoutSpec, TacksPresentSpec
from cell.scenario.turnover_specs import TurnoverPlacementSpec


class ProcessSpec(Model):
    """The arc welding process: speeds, torch angles and offsets (docs/reference.md sections 4 and 7).

    Angles follow the welding convention: the work angle is measured from face B (the receiving part's face) in
    the plane perpendicular to the seam; the travel angle tilts the torch along the seam, positive = push (the
    wire points ahead, in the weld direction), negative = drag.
    """

    travel_speed_mm_s: Annotated[float, Field(gt=0.0, le=100.0)] = 8.0  # MAG fillet 8-10 mm/s (section 4)
    work_angle_deg: Annotated[float, Field(gt=0.0, lt=90.0)] = 45.0  # 45 bisects a square fillet (section 4)
    work_angle_tol_deg: Annotated[float, Field(ge=0.0, le=30.0)] = 10.0  # how far the planner may move it
    travel_angle_deg: Annotated[float, Field(ge=-45.0, le=45.0)] = 10.0  # push 5-15 deg (section 4)
    # The planner tries the nominal angle first and widens in 5 deg steps up to this tolerance before it calls a
    # seam unreachable (section 7); past 5 deg it leaves section 4's 5-15 range (needed where a vertical seam
    # meets the table: the nozzle needs 20-25 deg there) and the plan reports the angle it used.
    travel_angle_tol_deg: Annotated[float, Field(ge=0.0, le=40.0)] = 20.0
    contact_tip_distance_mm: Annotated[float, Field(gt=0.0, le=50.0)] = 15.0  # CTWD 12-20 mm (section 4)
    spin_tol_deg: Annotated[float, Field(ge=0.0, le=180.0)] = 180.0  # rotation about the torch axis: free
    approach_mm: Annotated[float, Field(gt=0.0, le=500.0)] = 50.0  # back along the torch axis before the seam
    depart_mm: Annotated[float, Field(gt=0.0, le=500.0)] = 50.0  # back along the torch axis after the seam
    approach_speed_mm_s: Annotated[float, Field(gt=0.0, le=250.0)] = 250.0  # reduced speed, ISO 10218 (s. 7)
    leg_mm: Annotated[float, Field(gt=0.0, le=30.0)] = 4.0  # the fillet leg a seam asks for: picks its WPS row
    seam_leg_mm: dict[str, Annotated[float, Field(gt=0.0, le=30.0)]] = Field(default_factory=dict)  # per seam id
    # A closed curved seam (a tube all round a plate) is welded on past its start by this much, over the start's
    # bead, before the crater: the start and the stop overlap.
    closed_overlap_mm: Annotated[float, Field(ge=0.0, le=50.0)] = 10.0
    # A curved seam the arm cannot weld whole: ``manual`` welds the stretches it reaches (in arcs, each restart over
    # the last bead by the overlap) and lists the rest, with why, for a manual weld (the run is partial, exit 3);
    # ``refuse`` welds none of it. Curves only: a straight seam is welded whole or not at all.
    curve_remainder: Literal["manual", "refuse"] = "manual"


class PerceptionSpec(Model):
    """Splicing and preprocessing (paper sections 3.2-3.5), and the checks that turn bad data into reasons."""

    workspace: WorkspaceSpec
    icp_max_correspondence_m: Pos = 0.001  # paper: 1 mm
    icp_iterations: Annotated[int, Field(ge=1, le=1000)] = 50  # paper: 50
    splice_icp: Literal["paper", "robust"] = "robust"  # paper: point-to-point ICP; robust: point-to-plane, Tukey
    merge_cell_m: Pos = 0.05  # region size for "each region from the camera that sees it best"
    voxel_m: Pos = 0.01  # paper: 1 cm
    align_max_correspondence_m: Pos = 0.02  # map-to-cloud ICP
    align_iterations: Annotated[int, Field(ge=1, le=1000)] = 60
    align_min_fitness: Annotated[float, Field(ge=0.0, le=1.0)] = 0.5
    health: HealthOptions = HealthOptions()  # is a camera's data fit to splice (dead, stuck, garbage, bumped)
    symmetry: SymmetryOptions = SymmetryOptions()  # is the map's fit unique (no near-symmetry fits as well)
    coverage: CoverageOptions = CoverageOptions()  # does the aligned map lie on the cloud; which parts are missing
    screen: ScreenOptions = ScreenOptions()  # which found seams must not be welded (occluded, doubtful)


class RescanSpec(Model):
    """Close-up re-scan before welding and the weld gate (cell.rescan.fusion; calibration in its docstring).

    mode : ``low`` re-scans the seams whose confidence is below ``confidence_threshold`` or whose bound
        (``bound_sigmas`` sigma) exceeds ``weld_tolerance_mm`` (and visible seams not found), ``all`` every visible
        seam, ``none`` nothing.
    weld_tolerance_mm, bound_sigmas : after the re-scan, a seam whose locator's sigma (calibrated,
        cell/seams/sigma.py) times ``bound_sigmas`` exceeds ``weld_tolerance_mm`` is not welded (``low_confidence``).
    end_tolerance_mm : a seam whose end bound (``bound_sigmas`` times an end's sigma along the seam,
        ``SeamEstimate.end_sigma_m``) exceeds this is re-scanned in ``low`` mode and, still over after the re-scan, not
        welded (``end_uncertain``): a bead more than this past or short of its joint's end is a defect.
    weld_min_confidence : after the re-scan, a seam below this is not welded (reason ``low_confidence``).
    allow_loose_gate : the gate's figures may go beyond their sane range (``weld_tolerance_mm`` up to
        SANE_WELD_TOLERANCE_MM, ``end_tolerance_mm`` up to SANE_END_TOLERANCE_MM, ``bound_sigmas`` within
        SANE_BOUND_SIGMAS, in cell.config.rescan): without it such a figure is refused; with it
        ``cell scenario check`` warns that the gate is loose.
    escalate_mm : in ``low`` mode, a close-up that disagrees with the first estimate by more than this [mm]
        triggers a re-scan of every visible seam.
    closeup : how each close-up is taken, located and fused (:class:`~cell.config.rescan.RescanOptions`).
    """

    mode: Literal["none", "low", "all"] = "low"
    # Calibrated by benchmarks/bench_confidence.py (cell.config.rescan.CONFIDENCE_THRESHOLD says how).
    confidence_threshold: Annotated[float, Field(ge=0.0, le=1.0)] = CONFIDENCE_THRESHOLD
    weld_min_confidence: Annotated[float, Field(ge=0.0, le=1.0)] = 0.3
    weld_tolerance_mm: Annotated[float, Field(gt=0.0)] = WELD_TOLERANCE_MM
    bound_sigmas: Annotated[float, Field(gt=0.0)] = BOUND_SIGMAS
    end_tolerance_mm: Annotated[float, Field(gt=0.0)] = END_TOLERANCE_MM
    allow_loose_gate: bool = False  # opt in to gate figures beyond their sane range (then a warning, not an error)
    # A close-up that moves its seam further than this from the first estimate means the fixed cameras cannot be
    # trusted (calibration off, a bumped camera): every other visible seam is then re-scanned too.
    escalate_mm: Annotated[float, Field(gt=0.0)] = 0.5
    closeup: RescanOptions = RescanOptions()

    @property
    def max_sigma_m(self) -> float:
        """The largest sigma [m] a seam may have and be welded: ``weld_tolerance_mm`` / ``bound_sigmas``."""
        return self.weld_tolerance_mm / 1000.0 / self.bound_sigmas

    @property
    def max_end_sigma_m(self) -> float:
        """The largest sigma [m] of an end along the seam for the seam to be welded: ``end_tolerance_mm`` /
        ``bound_sigmas``."""
        return self.end_tolerance_mm / 1000.0 / self.bound_sigmas

    def loose_gate(self) -> list[str]:
        """The gate's figures beyond their sane range, one phrase each (empty when the gate is sane)."""
        lo, hi = SANE_BOUND_SIGMAS
        out = []
        if self.weld_tolerance_mm > SANE_WELD_TOLERANCE_MM:
            out.append(f"weld_tolerance_mm {self.weld_tolerance_mm:g} is over {SANE_WELD_TOLERANCE_MM:g}")
        if self.end_tolerance_mm > SANE_END_TOLERANCE_MM:
            out.append(f"end_tolerance_mm {self.end_tolerance_mm:g} is over {SANE_END_TOLERANCE_MM:g}")
        if not lo <= self.bound_sigmas <= hi:
            out.append(f"bound_sigmas {self.bound_sigmas:g} is outside {lo:g} to {hi:g}")
        return out

    @model_validator(mode="after")
    def _sane_gate(self) -> RescanSpec:
        loose = self.loose_gate()
        if loose and not self.allow_loose_gate:
            raise ValueError(
                f"{'; '.join(loose)}: the weld gate would be off in all but name; set allow_loose_gate: true to mean it"
            )
        return self

    @model_validator(mode="after")
    def _closeup_locator_options(self) -> RescanSpec:
        """Each method's close-up options must be options of that method (checked now, not at the re-scan)."""
        specs = {spec_method(s): s for s in LOCATOR_SPECS}
        for method, extra in self.closeup.closeup_locator_options.items():
            where = f"closeup.closeup_locator_options.{method}"
            spec = specs.get(method)
            if spec is None:
                raise ValueError(f"{where}: no locator {method!r}; valid: {', '.join(specs)}")
            valid = [f.name for f in dataclasses.fields(spec().options)]
            for key in extra:
                if key not in valid:
                    close = difflib.get_close_matches(key, valid, n=1)
                    hint = f" (did you mean {close[0]!r}?)" if close else ""
                    raise ValueError(f"{where}: unknown key {key!r}{hint}; valid keys there: {', '.join(valid)}")
            try:
                spec.model_validate({"method": method, "options": dict(extra)})
            except ValidationError as e:
                raise ValueError(f"{where}: {e.errors()[0]['msg']}") from None
        return self


class CameraFaultSpec(Model):
    """A simulated camera failure: what the camera delivers instead of a good image (for fault scenarios).

    ``dead``: no valid pixel (unplugged, blinded, laser off); ``random``: every pixel a random depth between
    near_m and far_m (corrupted stream); ``constant``: every pixel reads ``depth_m`` (a stuck sensor);
    ``salt``: ``fraction`` of the pixels replaced by random depths (a failing projector / interference).
    """

    mode: Literal["dead", "random", "constant", "salt"]
    fraction: Annotated[float, Field(gt=0.0, le=1.0)] = 0.3  # salt: share of pixels replaced
    depth_m: Pos = 1.0  # constant: the value every pixel reads [m]


class OccluderSpec(Model):
    """An object in the cell that the welding map does not know (a clamp, a cable): a box in the world [m]."""

    center_m: Vec3
    size_m: tuple[Pos, Pos, Pos]
    rpy_deg: Vec3 = (0.0, 0.0, 0.0)

    @property
    def X_WO(self) -> FloatArray:
        return pose_from_xyz_rpy(self.center_m, np.radians(self.rpy_deg))


class FaultsSpec(Model):
    """Faults to simulate (all empty by default: a healthy cell).

    cameras : camera name -> its failure. occluders : name -> a box the map does not know, rendered in every
    camera. missing_parts : parts of the map that were not built (not put on the table).
    The part placed off its nominal place is ``map.placement_error``; a camera knocked out of calibration is
    ``cameras.<name>.extrinsic_error``.
    """

    cameras: dict[str, CameraFaultSpec] = Field(default_factory=dict)
    occluders: dict[str, OccluderSpec] = Field(default_factory=dict)
    missing_parts: tuple[str, ...] = ()


class MotionSpec(Model):
    """Motion: the welding planner (with the collision model every motion of the run is checked against) and the
    safety gate the plan must pass."""

    plan: PlanOptions = PlanOptions()
    gate: GateOptions = GateOptions()


class ExportSpec(Model):
    """What the cell writes for the controller: the robot program (``cell weld --program``)."""

    krl: KrlOptions = KrlOptions()


class SimulationSpec(Model):
    """What only a simulation knows: how the part was really built and placed, the sensors' noise, the faults it
    plays, how it draws the weld. A real cell is told none of this; everything else in the scenario is what a real
    cell is told."""

    noise: Literal["none", "realistic"] = "realistic"  # the depth sensors' error model on or off
    deviations: dict[str, Deviation] = Field(default_factory=dict)  # part name -> as built minus drawn
    placement_error: PoseSpec = PoseSpec()  # where the part really lies, relative to map.X_WM (ground truth only)
    faults: FaultsSpec = FaultsSpec()
    bead: BeadStyle = BeadStyle()  # how the weld bead is drawn (no effect on any figure)
    flip_placement: TurnoverPlacementSpec = TurnoverPlacementSpec()  # the operator's error setting the turned part down
    gaps: GapsSpec | None = None  # joint gaps varying along the seams (docs/bodies.md section 7); null: as drawn
    tacks_present: TacksPresentSpec | None = None  # tack welds at both ends of every seam; null: none
    bow: tuple[BowSpec, ...] = ()  # bowed parts: one {part, mm} or a list of them; empty: every part straight
    specular_dropout: SpecularDropoutSpec | None = None  # shiny steel facing the cameras drops out; null: off
    # The calibration board as printed against its stated size (cell calibrate): 1.05 is a board 5 % larger
    board_scale: Annotated[float, Field(ge=0.5, le=2.0)] = 1.0

    @field_validator("bow", mode="before")
    @classmethod
    def _one_bow(cls, v: object) -> object:
        return (v,) if isinstance(v, dict) else v

    @field_validator("bow")
    @classmethod
    def _bow_once(cls, v: tuple[BowSpec, ...]) -> tuple[BowSpec, ...]:
        names = [b.part for b in v]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(f"simulation.bow: one bow per part; {', '.join(twice)} given more than once")
        return v
