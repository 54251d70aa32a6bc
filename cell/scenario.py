"""Scenario files: YAML -> validated, typed, frozen :class:`Scenario`.

Everything about a cell lives in a scenario file under ``scenarios/``, never in code. An unknown or misspelled key,
a value out of range or a missing file is a :class:`~cell.errors.ScenarioError` with a one-line message naming the
key and what is valid. Lengths in the file are metres (keys end in ``_m``) or millimetres (``_mm``), angles degrees
(``_deg``); :class:`Scenario` converts nothing implicitly: accessors named ``*_rad`` / ``X_*`` do it in one place.
"""

from __future__ import annotations

import difflib
import math
import zlib
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from cell.errors import ScenarioError
from cell.geometry import FloatArray, look_at, pose_from_xyz_rpy

REPO_ROOT = Path(__file__).resolve().parent.parent
SCENARIO_DIR = REPO_ROOT / "scenarios"

Vec3 = tuple[float, float, float]
NonNeg = Annotated[float, Field(ge=0.0)]
Pos = Annotated[float, Field(gt=0.0)]


class _Model(BaseModel):
    # Non-finite numbers (.nan, .inf in YAML) are rejected: they would turn poses into NaN (fuzzing found it).
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class PoseSpec(_Model):
    """A pose given as translation [m] and fixed-axis roll, pitch, yaw [deg]."""

    xyz_m: Vec3 = (0.0, 0.0, 0.0)
    rpy_deg: Vec3 = (0.0, 0.0, 0.0)

    @property
    def X(self) -> FloatArray:
        return pose_from_xyz_rpy(self.xyz_m, np.radians(self.rpy_deg))


class MapSpec(_Model):
    """The welding map: a DXF file (relative to the scenario file) and where its origin sits in the world."""

    file: str
    units: Literal["mm", "cm", "m", "in"] | None = None  # only used when the DXF declares no $INSUNITS
    X_WM: PoseSpec = PoseSpec()  # nominal placement of the drawing on the table (what the cell is told)
    placement_error: PoseSpec = PoseSpec()  # where the part really lies, relative to X_WM (ground truth only)


class Deviation(_Model):
    """How one part was built differently from the drawing (as-built minus designed), in the part's own frame."""

    size_mm: Vec3 = (0.0, 0.0, 0.0)
    offset_mm: Vec3 = (0.0, 0.0, 0.0)
    rpy_deg: Vec3 = (0.0, 0.0, 0.0)


class TableSpec(_Model):
    """The welding table, a box: centre and size in the world [m]."""

    center_m: Vec3
    size_m: tuple[Pos, Pos, Pos]

    @property
    def top_z(self) -> float:
        return self.center_m[2] + self.size_m[2] / 2.0


class RobotSpec(_Model):
    """Which robot and where its base stands (X_WR = pose of the robot base frame R in the world)."""

    urdf: str | None = None  # relative to the repository's robots/ folder; None: no arm in the cell
    X_WR: PoseSpec = PoseSpec()
    home_deg: tuple[float, ...] | None = None
    # Wire stick-out [mm] beyond the contact tip in the URDF's torch_tcp (robots/build_kr5_arc.py STICKOUT): the
    # torch planner stands the TCP off the seam by contact_tip_distance_mm minus this (0 by default).
    stickout_mm: Pos = 15.0


class ProcessSpec(_Model):
    """The arc welding process: speeds, torch angles and offsets (REFERENCE.md sections 4 and 7).

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


class NoiseSpec(_Model):
    """Depth sensor model (REFERENCE.md section 2). ``active_stereo`` follows the RealSense D4xx error model."""

    model: Literal["none", "active_stereo", "structured_light"] = "active_stereo"
    baseline_m: Pos = 0.055  # D415 [m]
    subpixel_px: NonNeg = 0.08  # RMS subpixel disparity error [px]
    disparity_step_px: NonNeg = 1.0 / 32.0  # disparity quantisation [px]
    depth_unit_m: NonNeg = 0.0001  # depth output quantisation [m]
    edge_invalid_fraction: Annotated[float, Field(ge=0.0, le=1.0)] = 0.09  # at depth discontinuities
    edge_flying_fraction: Annotated[float, Field(ge=0.0, le=1.0)] = 0.5  # of those, how many come back mixed
    edge_jump_m: Pos = 0.02  # depth step that counts as a discontinuity [m]
    grazing_dropout_deg: Annotated[float, Field(gt=0.0, le=90.0)] = 80.0  # incidence beyond which pixels drop


class ExtrinsicErrorSpec(_Model):
    """Calibration error of a camera pose: magnitudes, directions drawn from the scenario seed."""

    translation_mm: NonNeg = 0.0
    rotation_deg: NonNeg = 0.0


class CameraSpec(_Model):
    """A depth camera looking from ``eye_m`` at ``target_m`` (world) with a pinhole of the given size and field."""

    mount: Literal["fixed", "eye_in_hand"] = "fixed"
    eye_m: Vec3
    target_m: Vec3
    up: Vec3 = (0.0, 0.0, 1.0)
    resolution: tuple[Annotated[int, Field(ge=16, le=4096)], Annotated[int, Field(ge=16, le=4096)]] = (
        1280,
        720,
    )
    hfov_deg: Annotated[float, Field(gt=1.0, lt=170.0)] = 65.0
    near_m: Annotated[float, Field(ge=0.05)] = 0.1
    far_m: Pos = 4.0
    noise: NoiseSpec = NoiseSpec()
    extrinsic_error: ExtrinsicErrorSpec = ExtrinsicErrorSpec()

    @model_validator(mode="after")
    def _check(self) -> CameraSpec:
        if self.far_m <= self.near_m:
            raise ValueError(f"far_m ({self.far_m}) must be greater than near_m ({self.near_m})")
        if math.dist(self.eye_m, self.target_m) < 1e-6:
            raise ValueError("eye_m and target_m coincide")
        return self

    @property
    def X_WC(self) -> FloatArray:
        """True pose of the optical frame in the world."""
        return look_at(self.eye_m, self.target_m, self.up)

    @property
    def fx_px(self) -> float:
        return 0.5 * self.resolution[0] / math.tan(math.radians(self.hfov_deg) / 2.0)


class WorkspaceSpec(_Model):
    """Passthrough crop in the world [m]: only points inside this box are kept (paper eq. 2)."""

    min_m: Vec3
    max_m: Vec3

    @model_validator(mode="after")
    def _check(self) -> WorkspaceSpec:
        if any(lo >= hi for lo, hi in zip(self.min_m, self.max_m, strict=True)):
            raise ValueError(f"workspace min_m {self.min_m} must be below max_m {self.max_m} on every axis")
        return self


class PerceptionSpec(_Model):
    """Splicing and preprocessing (paper sections 3.2-3.5)."""

    workspace: WorkspaceSpec
    icp_max_correspondence_m: Pos = 0.001  # paper: 1 mm
    icp_iterations: Annotated[int, Field(ge=1, le=1000)] = 50  # paper: 50
    splice_icp: Literal["paper", "robust"] = "robust"  # paper: point-to-point ICP; robust: point-to-plane, Tukey
    merge_cell_m: Pos = 0.05  # region size for "each region from the camera that sees it best"
    voxel_m: Pos = 0.01  # paper: 1 cm
    align_max_correspondence_m: Pos = 0.02  # map-to-cloud ICP
    align_iterations: Annotated[int, Field(ge=1, le=1000)] = 60
    align_min_fitness: Annotated[float, Field(ge=0.0, le=1.0)] = 0.5


class PaperLocatorSpec(_Model):
    """Options of the paper's locator (section 3.6); masks are (across, along) half-widths... as in eq. 5-6 [m]."""

    outer_mask_m: tuple[Pos, Pos] = (0.03, 0.05)
    inner_mask_m: tuple[Pos, Pos] = (0.015, 0.03)
    frequency_bin_m: Pos = 0.001


class LocatorSpec(_Model):
    """Which locator runs by default and its options."""

    method: Literal["paper", "ransac", "ours"] = "ours"  # ours beats both (README, cell bench)
    paper: PaperLocatorSpec = PaperLocatorSpec()
    options: dict[str, dict[str, float | int | str | bool]] = Field(default_factory=dict)


class RescanSpec(_Model):
    """Close-up re-scan before welding and the confidence gate (cell.rescan; calibration in its docstring).

    mode : ``low`` re-scans the seams whose confidence is below ``confidence_threshold`` (and visible seams not
        found), ``all`` every visible seam, ``none`` nothing.
    weld_min_confidence : after the re-scan, a seam below this is not welded (reason ``low_confidence``).
    escalate_mm : in ``low`` mode, a close-up that disagrees with the first estimate by more than this [mm]
        triggers a re-scan of every visible seam.
    """

    mode: Literal["none", "low", "all"] = "low"
    confidence_threshold: Annotated[float, Field(ge=0.0, le=1.0)] = 0.55  # benchmarks/bench_confidence.py
    weld_min_confidence: Annotated[float, Field(ge=0.0, le=1.0)] = 0.3
    # A close-up that moves its seam further than this from the first estimate means the fixed cameras cannot be
    # trusted (calibration off, a bumped camera): every other visible seam is then re-scanned too.
    escalate_mm: Annotated[float, Field(gt=0.0)] = 0.5


class CameraFaultSpec(_Model):
    """A simulated camera failure: what the camera delivers instead of a good image (for fault scenarios).

    ``dead``: no valid pixel (unplugged, blinded, laser off); ``random``: every pixel a random depth between
    near_m and far_m (corrupted stream); ``constant``: every pixel reads ``depth_m`` (a stuck sensor);
    ``salt``: ``fraction`` of the pixels replaced by random depths (a failing projector / interference).
    """

    mode: Literal["dead", "random", "constant", "salt"]
    fraction: Annotated[float, Field(gt=0.0, le=1.0)] = 0.3  # salt: share of pixels replaced
    depth_m: Pos = 1.0  # constant: the value every pixel reads [m]


class OccluderSpec(_Model):
    """An object in the cell that the welding map does not know (a clamp, a cable): a box in the world [m]."""

    center_m: Vec3
    size_m: tuple[Pos, Pos, Pos]
    rpy_deg: Vec3 = (0.0, 0.0, 0.0)

    @property
    def X_WO(self) -> FloatArray:
        return pose_from_xyz_rpy(self.center_m, np.radians(self.rpy_deg))


class FaultsSpec(_Model):
    """Faults to simulate (all empty by default: a healthy cell).

    cameras : camera name -> its failure. occluders : name -> a box the map does not know, rendered in every
    camera. missing_parts : parts of the map that were not built (not put on the table).
    The part placed off its nominal place is ``map.placement_error``; a camera knocked out of calibration is
    ``cameras.<name>.extrinsic_error``.
    """

    cameras: dict[str, CameraFaultSpec] = Field(default_factory=dict)
    occluders: dict[str, OccluderSpec] = Field(default_factory=dict)
    missing_parts: tuple[str, ...] = ()


class Scenario(_Model):
    """A whole cell: map, as-built part, table, robot, cameras, seed and algorithm options."""

    name: str
    description: str = ""
    seed: Annotated[int, Field(ge=0)]
    noise: Literal["none", "realistic"] = "realistic"
    map: MapSpec
    deviations: dict[str, Deviation] = Field(default_factory=dict)
    table: TableSpec
    robot: RobotSpec = RobotSpec()
    process: ProcessSpec = ProcessSpec()
    cameras: dict[str, CameraSpec]
    perception: PerceptionSpec
    locator: LocatorSpec = LocatorSpec()
    rescan: RescanSpec = RescanSpec()
    faults: FaultsSpec = FaultsSpec()
    # Set by the loader: the folder the file lives in (paths inside are relative to it).
    base_dir: str = Field(default=".", exclude=True)

    @field_validator("cameras")
    @classmethod
    def _cameras(cls, v: dict[str, CameraSpec]) -> dict[str, CameraSpec]:
        if not v:
            raise ValueError("at least one camera is needed")
        return v

    @model_validator(mode="after")
    def _fault_cameras(self) -> Scenario:
        unknown = sorted(set(self.faults.cameras) - set(self.cameras))
        if unknown:
            raise ValueError(
                f"faults.cameras names unknown camera(s) {', '.join(unknown)}; cameras: {', '.join(self.cameras)}"
            )
        return self

    @property
    def map_path(self) -> Path:
        return (Path(self.base_dir) / self.map.file).resolve()

    @property
    def X_WR(self) -> FloatArray:
        return self.robot.X_WR.X

    @property
    def X_WM(self) -> FloatArray:
        return self.map.X_WM.X

    def rng(self, purpose: str) -> np.random.Generator:
        """An independent, reproducible random stream for one consumer (camera name, 'ransac', ...).

        Streams are keyed by the scenario seed and a stable hash of ``purpose``, so adding a consumer never
        changes the numbers another consumer draws. There is no global RNG anywhere in the cell.
        """
        return np.random.default_rng([self.seed, zlib.crc32(purpose.encode())])

    def with_noise(self, noise: Literal["none", "realistic"]) -> Scenario:
        return self.model_copy(update={"noise": noise})


def _format_loc(loc: tuple[int | str, ...]) -> str:
    return ".".join(str(p) for p in loc) or "<top level>"


def _valid_keys(model: type[BaseModel], loc: tuple[int | str, ...]) -> list[str]:
    """Field names valid at ``loc`` (the location of an unknown key), by walking the model tree."""
    current: Any = model
    free_key = False  # the next part of loc is a free dict key (a camera or part name)
    for part in loc[:-1]:
        if free_key:
            free_key = False
            continue
        if not (isinstance(current, type) and issubclass(current, BaseModel)) or not isinstance(part, str):
            return []
        f = current.model_fields.get(part)
        if f is None:
            return []
        ann = f.annotation
        args = getattr(ann, "__args__", ())
        free_key = getattr(ann, "__origin__", None) is dict
        # dict[str, Model] -> Model after the free key; Model | None -> Model
        candidates = [a for a in (ann, *args) if isinstance(a, type) and issubclass(a, BaseModel)]
        current = candidates[0] if candidates else ann
    if isinstance(current, type) and issubclass(current, BaseModel):
        return [k for k in current.model_fields if k != "base_dir"]
    return []


def _explain(err: ValidationError, source: str) -> str:
    errors = err.errors()
    # An unknown (misspelled) key explains the rest (the real key then shows up as missing): report it first.
    e = next((x for x in errors if x["type"] == "extra_forbidden"), errors[0])
    loc = tuple(e["loc"])
    where = _format_loc(loc)
    if e["type"] == "extra_forbidden":
        valid = _valid_keys(Scenario, loc)
        close = difflib.get_close_matches(str(loc[-1]), valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{source}: unknown key {where!r}{hint}; valid keys there: {', '.join(valid)}"
    if e["type"] == "missing":
        return f"{source}: missing key {where!r}"
    more = f" (+{len(errors) - 1} more problems)" if len(errors) > 1 else ""
    return f"{source}: {where}: {e['msg']} (got {e.get('input')!r}){more}"


def resolve(name_or_path: str | Path) -> Path:
    """``fence1`` -> ``scenarios/fence1.yaml``; a path is taken as is."""
    p = Path(name_or_path)
    if p.suffix in (".yaml", ".yml") or p.exists():
        if not p.is_file():
            raise ScenarioError(f"scenario file {str(p)!r} does not exist")
        return p
    candidate = SCENARIO_DIR / f"{name_or_path}.yaml"
    if candidate.is_file():
        return candidate
    known = ", ".join(available())
    raise ScenarioError(f"no scenario named {str(name_or_path)!r}; available: {known}")


def available() -> list[str]:
    """Names of the scenarios shipped in ``scenarios/`` (sub-folders as ``faults/name``)."""
    return sorted(str(p.relative_to(SCENARIO_DIR).with_suffix("")) for p in SCENARIO_DIR.rglob("*.yaml"))


def from_dict(data: Any, base_dir: Path, source: str = "<scenario>") -> Scenario:
    """Validate a parsed YAML mapping into a :class:`Scenario`; paths inside resolve against ``base_dir``."""
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: a scenario must be a YAML mapping of keys, got {type(data).__name__}")
    try:
        scenario = Scenario.model_validate({**data, "base_dir": str(base_dir)})
    except ValidationError as err:
        raise ScenarioError(_explain(err, source)) from None
    if not scenario.map_path.is_file():
        raise ScenarioError(f"{source}: map.file {scenario.map.file!r} does not exist (looked at {scenario.map_path})")
    return scenario


def from_yaml(text: str, base_dir: Path = SCENARIO_DIR, source: str = "<inline>") -> Scenario:
    """Parse and validate scenario YAML text (used by tests for tiny inline scenarios)."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise ScenarioError(f"{source}: not valid YAML{where}: {getattr(err, 'problem', err)}") from None
    return from_dict(data, base_dir, source)


def load(name_or_path: str | Path) -> Scenario:
    """Load a scenario by name (``fence1``) or path."""
    path = resolve(name_or_path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ScenarioError(f"cannot read scenario {str(path)!r}: {err}") from None
    return from_yaml(text, path.parent, str(path.name))
