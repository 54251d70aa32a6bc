"""What a run of the pipeline produces: the capture, the perceived scene, the detection and the weld run.

Values only (frozen dataclasses); the stages that fill them live beside this module.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from cell.errors import CellError
from cell.geometry import FloatArray
from cell.scenario import Scenario
from cell.station.ports import Arm
from cell.types import (
    DepthImage,
    Joint,
    MetricsSummary,
    Part,
    SeamEstimate,
    SeamMetrics,
    SeamScene,
    SeamStatus,
    Unsupported,
    UnsupportedSeam,
    Violation,
    WeldMap,
)
from cell.types.curve_estimate import CurveEstimate, CurveMetrics
from cell.types.run import SeamRecord, SeamWeld, WeldReason

if TYPE_CHECKING:
    from cell.perception import Alignment, Perceived
    from cell.types.execution import Execution
    from cell.types.plan import WeldPlan
    from cell.types.rescan import PlannedCloseup, Rescan
    from cell.types.trajectory import Trajectory
    from cell.types.view import CellView


@dataclass(frozen=True)
class Capture:
    """What the cameras saw, the map the pipeline read, and the ground truth when the station knows it (the
    simulator does; it is never handed to perception)."""

    scenario: Scenario
    weldmap: WeldMap  # as drawn, frame M
    joints: Mapping[str, Joint]  # seam id -> how it is made (topological: valid in every frame of the map)
    parts_W: tuple[Part, ...] | None  # as built, world frame (ground truth), None when unknown
    images: Mapping[str, DepthImage]
    seconds: float
    source: str = "simulation"  # where the images came from (Station.source)


@dataclass(frozen=True)
class Scene:
    """The perceived cell: spliced clouds, the aligned map and the seam scene the locators read."""

    seam_scene: SeamScene
    perceived: Perceived
    alignment: Alignment
    X_RM: FloatArray  # pose of the aligned map in the robot frame
    timings: dict[str, float]
    missing: Mapping[str, str] = field(default_factory=dict)  # parts of the map not in the cloud -> why


@dataclass(frozen=True)
class Detection:
    """The outcome of ``cell detect``: estimates, truths and metrics per seam, in the robot frame R."""

    scenario: Scenario
    method: str
    weldmap_R: WeldMap
    estimates: tuple[SeamEstimate, ...]
    truths: Mapping[str, tuple[FloatArray, FloatArray]]
    metrics: Mapping[str, SeamMetrics]  # found seams only
    summary: MetricsSummary
    timings: dict[str, float] = field(default_factory=dict)
    lost_cameras: tuple[str, ...] = ()
    scene: Scene | None = None
    error: CellError | None = None  # perception or alignment failed: no seam was searched (report still written)
    perceived: Perceived | None = None  # the clouds perceived when the alignment failed (None otherwise: see scene)
    joints: Mapping[str, Joint] = field(default_factory=dict)  # seam id -> how it is made
    source: str = "simulation"  # the data's origin: simulation | capture (replayed) | cloud (brought) | camera
    curve_truths: Mapping[str, FloatArray] = field(default_factory=dict)  # curved seam id -> true curve (n, 3) in R
    curve_estimates: tuple[CurveEstimate, ...] = ()  # one per curved seam of the map, in its order
    curve_metrics: Mapping[str, CurveMetrics] = field(default_factory=dict)  # found curved seams with a truth

    curve_welds: Mapping[str, SeamWeld] = field(default_factory=dict)  # a weld run's word on each located curve

    @property
    def not_welded(self) -> tuple[UnsupportedSeam, ...]:
        """Every seam of the map this run will not weld, with its reason (:attr:`WeldMap.not_straight`), a curved
        seam's from its estimate and the weld run (``curve_welds``): welded, it is left out; welded in part,
        ``partial`` (the remainder left for a manual weld in its reason); tried and not welded, the planner's code
        (or the weld's: ``preview``, ``not_executed``); located and never tried (a detection),
        ``curved_no_torch_path``; not located, why not (``curved_not_located``)."""
        curves = {e.id: e for e in self.curve_estimates}
        out = []
        for u in self.weldmap_R.not_straight:
            e, w = curves.get(u.id), self.curve_welds.get(u.id)
            drawn = u.reason.rsplit("; ", 1)[0]  # where and what it is, without the map's "not located"
            if e is None:
                out.append(u)
            elif w is not None and w.welded:
                continue
            elif w is not None and w.code is WeldReason.PARTIAL:
                out.append(UnsupportedSeam(u.id, f"{drawn}: located; {w.reason}", w.code))
            elif w is not None:
                code = w.plan_code or w.code or WeldReason.NOT_PLANNED
                out.append(UnsupportedSeam(u.id, f"{drawn}: located; not welded: {w.reason}", code))
            elif e.status is SeamStatus.FOUND:
                sigma = f"sigma up to {e.sigma_max_m * 1000:.2f} mm"
                why = f"{drawn}: located ({sigma}); no torch path planned (this run plans no weld)"
                out.append(UnsupportedSeam(u.id, why, Unsupported.CURVED_NO_TORCH_PATH))
            else:
                out.append(UnsupportedSeam(u.id, f"{drawn}; {e.reason}", Unsupported.CURVED_NOT_LOCATED))
        return tuple(out)

    def records(self) -> tuple[SeamRecord, ...]:
        """One :class:`~cell.types.SeamRecord` per seam of the map, in map order: seam, joint, estimate, truth,
        metrics."""
        return tuple(
            SeamRecord(
                seam=self.weldmap_R.seam(e.id),
                joint=self.joints.get(e.id),
                estimate=e,
                truth=self.truths.get(e.id),
                metrics=self.metrics.get(e.id),
            )
            for e in self.estimates
        )

    @property
    def complete(self) -> bool:
        """Every seam that can be seen was found, with every camera working (a lost camera is a degraded run), and
        the map holds no seam the cell cannot weld (a curve: listed, never dropped in silence)."""
        undone = (SeamStatus.NOT_FOUND, SeamStatus.OCCLUDED)
        found = all(e.status not in undone for e in self.estimates)
        return not self.lost_cameras and found and not self.not_welded


@dataclass(frozen=True, kw_only=True)
class WeldRun:
    """The outcome of ``cell weld`` / ``cell preview`` (built by keyword).

    plan : the checked welding plan (None when planning failed as a whole: see ``error``).
    execution : what the simulated arm did (None for a preview or when the gate refused the plan).
    error : the failure that stopped the run after detection, or None; the rest of the run is still reported.
    """

    detection: Detection
    seams: tuple[SeamWeld, ...]
    plan: WeldPlan | None = None
    pre_move: Trajectory | None = None
    execution: Execution | None = None
    violations: tuple[Violation, ...] = ()  # the safety gate's, in its order (the plan was refused)
    error: CellError | None = None
    timings: dict[str, float] = field(default_factory=dict)
    torch_paths: Mapping[str, FloatArray] = field(default_factory=dict)  # seam id -> (n, 4, 4) planned X_RT
    arm: Arm | None = None  # the robot that ran (the program post-processor needs its model; pictures read view)
    first_detection: Detection | None = None  # before the re-scan (the same as detection when none ran)
    rescan: Rescan | None = None
    view: CellView | None = None  # the table, the robot's shapes at its poses and the cameras, for pictures
    closeups: tuple[PlannedCloseup, ...] = ()  # a preview's planned close-up views (cell weld would take them)

    @property
    def cycle_time_s(self) -> float:
        """Robot time of everything the arm did: re-scan moves and the welding program [s] (0 when nothing moved)."""
        if self.execution is None:
            return 0.0
        return self.execution.duration + (self.rescan.motion_s if self.rescan is not None else 0.0)

    def records(self) -> tuple[SeamRecord, ...]:
        """One :class:`~cell.types.SeamRecord` per seam, in map order, with everything the run knows of it: the
        detection's record, the estimate before the re-scan and what the close-up did, the planner's outcome and
        the weld."""
        rescans = {r.id: r for r in self.rescan.seams} if self.rescan is not None else {}
        first = self.first_detection
        outcomes = {o.seam_id: o for o in self.plan.seams} if self.plan is not None else {}
        welds = {w.id: w for w in self.seams}
        out = []
        for rec in self.detection.records():
            r = rescans.get(rec.id)
            out.append(
                replace(
                    rec,
                    first=r.before if r is not None else None,
                    first_metrics=first.metrics.get(rec.id) if r is not None and first is not None else None,
                    rescan=r,
                    outcome=outcomes.get(rec.id),
                    weld=welds.get(rec.id),
                )
            )
        return tuple(out)

    @property
    def complete(self) -> bool:
        """Every seam that can be seen was welded (for a preview: planned) and nothing failed."""
        vis = [r.weld for r in self.records() if r.estimate.status is not SeamStatus.NOT_VISIBLE]
        executed = self.execution is not None
        done = all(w is not None and (w.welded if executed else w.planned) for w in vis)
        return self.error is None and self.detection.complete and done
