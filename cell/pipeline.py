"""The only place that knows the order of the stages: capture -> perceive -> align map -> locate -> plan -> execute.

Each stage is a function taking values and returning values; this module wires them and times them. The CLI is a thin
layer over :func:`detect` (and, for the bench, over :func:`capture`, :func:`build_scene` and :func:`locate`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Literal

from cell.errors import AlignmentError, CellError, PlanError, ScenarioError, SensorError
from cell.geometry import FloatArray, invert
from cell.motion.quality import WeldQuality
from cell.scenario import Scenario
from cell.seams.base import SeamScene
from cell.seams.metrics import MetricsSummary, SeamMetrics
from cell.station import Arm, Station
from cell.types import DepthImage, Part, SeamEstimate, SeamStatus, WeldMap

if TYPE_CHECKING:  # heavy imports stay inside the stages that need them
    from cell.motion.plan import WeldPlan
    from cell.motion.timing import Trajectory
    from cell.perception import Alignment, Perceived
    from cell.rescan import Rescan
    from cell.sim.robot import Execution

Progress = Callable[[str], None]


def _quiet(_: str) -> None:
    return None


@dataclass(frozen=True)
class Capture:
    """What the cameras saw, plus the ground truth the simulator knows (never handed to perception)."""

    scenario: Scenario
    weldmap: WeldMap  # as drawn, frame M
    parts_W: tuple[Part, ...]  # as built, world frame (ground truth)
    images: Mapping[str, DepthImage]
    seconds: float


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

    @property
    def complete(self) -> bool:
        """Every seam that can be seen was found, with every camera working (a lost camera is a degraded run)."""
        undone = (SeamStatus.NOT_FOUND, SeamStatus.OCCLUDED)
        return not self.lost_cameras and all(e.status not in undone for e in self.estimates)


def capture(
    scenario: Scenario, *, gui: bool = False, progress: Progress = _quiet, station: Station | None = None
) -> Capture:
    """Take one image with every camera of the scenario's cell (built here unless a running ``station`` is given).

    With a robot in the scenario, the arm first moves to its scan configuration: the eye-in-hand camera rides on
    it. The capture keeps the as-built parts (ground truth) for measuring, never for perception.
    """
    t0 = time.perf_counter()
    if station is None:
        progress(f"building the cell of {scenario.name}")
        with Station(scenario, gui=gui) as st:
            return capture(scenario, progress=progress, station=st)
    progress(f"rendering {len(scenario.cameras)} depth cameras ({scenario.noise} noise)")
    images = station.capture()
    return Capture(scenario, station.weldmap, station.parts_W, images, time.perf_counter() - t0)


def build_scene(cap: Capture, *, progress: Progress = _quiet) -> Scene:
    """Perceive (deproject, splice, filter, downsample), align the map to the cloud, and pair seams with joints."""
    from cell.perception import align_map, perceive
    from cell.perception.health import check_alignment_unique, check_parts_seen
    from cell.seams.joint import find_joints

    sc = cap.scenario
    timings: dict[str, float] = {}
    t = time.perf_counter()
    progress("splicing point clouds")
    perceived = perceive(cap.images, sc.X_WR, sc.perception)
    timings["perceive_s"] = time.perf_counter() - t

    t = time.perf_counter()
    progress("aligning the welding map to the cloud")
    X_RM_nominal = invert(sc.X_WR) @ sc.X_WM
    weldmap_nominal_R = cap.weldmap.transformed(X_RM_nominal, "R")
    # Alignment and our locator read every camera's registered points (the unmerged cloud): the paper's merge keeps
    # one camera per region and throws away good data; the paper's method keeps its merged, downsampled cloud.
    alignment = align_map(weldmap_nominal_R, perceived.registered, sc.perception)
    X_RM = alignment.X_RR_corr @ X_RM_nominal
    weldmap_R = cap.weldmap.transformed(X_RM, "R")
    # A fit that a near-symmetry explains as well (a ladder one rung off) or a map half off the cloud is refused;
    # parts that are simply not there are named, and their seams are never searched.
    check_alignment_unique(weldmap_R, perceived.registered, alignment)
    missing = check_parts_seen(weldmap_R, perceived.registered, sc.perception)
    joints = find_joints(weldmap_R)
    timings["align_s"] = time.perf_counter() - t

    table_z_R = float((invert(sc.X_WR) @ [0.0, 0.0, sc.table.top_z, 1.0])[2])
    seam_scene = SeamScene(
        cloud=perceived.downsampled,
        dense=perceived.registered,
        weldmap=weldmap_R,
        joints=joints,
        table_z=table_z_R,
        dense_voxels=perceived.registered_voxels,
    )
    return Scene(seam_scene, perceived, alignment, X_RM, timings, missing)


def locate(scene: Scene, scenario: Scenario, method: str, *, progress: Progress = _quiet) -> tuple[SeamEstimate, ...]:
    """Run one locator over every seam of the aligned map; seams no camera can see are reported, not searched."""
    from cell.perception.health import screen
    from cell.seams.base import BatchSeamLocator
    from cell.seams.registry import make_locator
    from cell.seams.visibility import visibility

    ss = scene.seam_scene
    locator = make_locator(method, scenario)
    rng = scenario.rng(f"locator/{method}")
    progress(f"locating {len(ss.weldmap.seams)} seams ({method})")
    hidden: dict[str, SeamEstimate] = {}
    for seam in ss.weldmap.seams:
        visible, reason = visibility(ss.weldmap, ss.joints[seam.id], ss.table_z)
        if not visible:
            hidden[seam.id] = SeamEstimate(seam.id, SeamStatus.NOT_VISIBLE, reason)
    seams = [seam for seam in ss.weldmap.seams if seam.id not in hidden]
    timed: dict[str, SeamEstimate] = {}
    if isinstance(locator, BatchSeamLocator) and seams:
        # Found together: each seam is charged an equal share of the whole batch's time.
        t = time.perf_counter()
        found = locator.locate_many(ss, seams, rng)
        dt = (time.perf_counter() - t) / len(seams)
        timed = {est.id: replace(est, time_s=dt) for est in found}
    else:
        for seam in seams:
            t = time.perf_counter()
            est = locator.locate(ss, seam, rng)
            timed[seam.id] = replace(est, time_s=time.perf_counter() - t)
    out = tuple(hidden[seam.id] if seam.id in hidden else timed[seam.id] for seam in ss.weldmap.seams)
    # Missing parts, occluders (points the map does not explain) and near-zero confidence: never a guess.
    return screen(ss, out, scene.missing)


def truths(cap: Capture, weldmap_R: WeldMap) -> dict[str, tuple[FloatArray, FloatArray]]:
    """True seams from the as-built geometry, in R, keyed by seam id."""
    from cell.seams.joint import find_joints
    from cell.seams.truth import true_seams

    design_W = cap.weldmap.transformed(cap.scenario.X_WM, "W")
    joints = find_joints(design_W)
    return true_seams(design_W, joints, cap.parts_W, cap.scenario.X_WR)


def evaluate(
    estimates: Sequence[SeamEstimate], truth: Mapping[str, tuple[FloatArray, FloatArray]]
) -> tuple[dict[str, SeamMetrics], MetricsSummary]:
    """Per-seam metrics of the found seams and the summary (paper ME, endpoint, lateral, time)."""
    from cell.seams.metrics import evaluate as metrics_of
    from cell.seams.metrics import summarise

    per_seam = metrics_of(estimates, truth)
    return per_seam, summarise(estimates, per_seam)


def detect(
    scenario: Scenario,
    method: str | None = None,
    *,
    noise: Literal["none", "realistic"] | None = None,
    progress: Progress = _quiet,
    gui: bool = False,
    station: Station | None = None,
) -> Detection:
    """Capture, perceive, align and locate every seam of the scenario's welding map; measure against truth."""
    if noise is not None:
        scenario = scenario.with_noise(noise)
    method = method or scenario.locator.method
    t_all = time.perf_counter()
    cap = capture(scenario, gui=gui, progress=progress, station=station)
    try:
        scene = build_scene(cap, progress=progress)
    except (SensorError, AlignmentError) as e:
        # No seam can be searched, but every seam is still reported, with the reason; nothing is invented.
        progress(f"no seam search: {e.message}")
        return _failed_detection(cap, method, e, time.perf_counter() - t_all)
    estimates = locate(scene, scenario, method, progress=progress)
    weldmap_R = scene.seam_scene.weldmap
    truth = truths(cap, weldmap_R)
    metrics, summary = evaluate(estimates, truth)
    timings = {"capture_s": cap.seconds, **scene.timings}
    timings["locate_s"] = sum(e.time_s for e in estimates)
    timings["total_s"] = time.perf_counter() - t_all
    return Detection(
        scenario=scenario,
        method=method,
        weldmap_R=weldmap_R,
        estimates=estimates,
        truths=truth,
        metrics=metrics,
        summary=summary,
        timings=timings,
        lost_cameras=tuple(scene.perceived.lost_described()),
        scene=scene,
    )


def _failed_detection(cap: Capture, method: str, error: CellError, seconds: float) -> Detection:
    """A detection whose perception or alignment failed: every seam NOT_FOUND (underside ones NOT_VISIBLE, which
    the drawing alone tells) with the reason, against the nominal map."""
    from cell.seams.joint import find_joints
    from cell.seams.visibility import visibility

    sc = cap.scenario
    X_RW = invert(sc.X_WR)
    weldmap_R = cap.weldmap.transformed(X_RW @ sc.X_WM, "R")
    joints = find_joints(weldmap_R)
    table_z = float((X_RW @ [0.0, 0.0, sc.table.top_z, 1.0])[2])
    estimates = []
    for seam in weldmap_R.seams:
        visible, why = visibility(weldmap_R, joints[seam.id], table_z)
        status = SeamStatus.NOT_FOUND if visible else SeamStatus.NOT_VISIBLE
        estimates.append(SeamEstimate(seam.id, status, f"no seam search: {error.message}" if visible else why))
    truth = truths(cap, weldmap_R)
    metrics, summary = evaluate(estimates, truth)
    return Detection(
        scenario=sc,
        method=method,
        weldmap_R=weldmap_R,
        estimates=tuple(estimates),
        truths=truth,
        metrics=metrics,
        summary=summary,
        timings={"capture_s": cap.seconds, "total_s": seconds},
        error=error,
    )


# -- plan and execute ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SeamWeld:
    """What became of one seam in ``cell weld``: planned and welded, or why not; how well (executed TCP vs the true
    seam)."""

    id: str
    planned: bool
    welded: bool
    reason: str = ""
    quality: WeldQuality | None = None


@dataclass(frozen=True)
class WeldRun:
    """The outcome of ``cell weld`` / ``cell preview``.

    plan : the checked welding plan (None when planning failed as a whole: see ``error``).
    execution : what the simulated arm did (None for a preview or when the gate refused the plan).
    error : the failure that stopped the run after detection, or None; the rest of the run is still reported.
    """

    detection: Detection
    seams: tuple[SeamWeld, ...]
    plan: WeldPlan | None = None
    pre_move: Trajectory | None = None
    execution: Execution | None = None
    violations: tuple[str, ...] = ()
    error: CellError | None = None
    timings: dict[str, float] = field(default_factory=dict)
    torch_paths: Mapping[str, FloatArray] = field(default_factory=dict)  # seam id -> (n, 4, 4) planned X_RT
    arm: Arm | None = None
    first_detection: Detection | None = None  # before the re-scan (the same as detection when none ran)
    rescan: Rescan | None = None

    @property
    def cycle_time_s(self) -> float:
        """Robot time of everything the arm did: re-scan moves and the welding program [s] (0 when nothing moved)."""
        if self.execution is None:
            return 0.0
        return self.execution.duration + (self.rescan.motion_s if self.rescan is not None else 0.0)

    @property
    def complete(self) -> bool:
        """Every seam that can be seen was welded (for a preview: planned) and nothing failed."""
        vis = [
            w
            for w, e in zip(self.seams, self.detection.estimates, strict=True)
            if e.status is not SeamStatus.NOT_VISIBLE
        ]
        executed = self.execution is not None
        done = all(w.welded if executed else w.planned for w in vis)
        return self.error is None and self.detection.complete and done


def plan_for(
    station: Station,
    det: Detection,
    *,
    skip: Collection[str] = (),
    q_start: FloatArray | None = None,
    progress: Progress = _quiet,
) -> tuple[WeldPlan, Trajectory, tuple[str, ...]]:
    """Plan the found seams of a detection (but those in ``skip``) and run the safety gate (REFERENCE section 7).

    q_start : where the arm is now (default: its scan configuration). Returns the plan, the move from q_start to
    home that precedes it, and the gate's violations (empty when the plan may run). PlanError when nothing can be
    planned at all.
    """
    from cell.motion.checks import find_violations
    from cell.motion.collision import CollisionChecker
    from cell.motion.plan import cell_obstacles, plan_welds, seam_tasks
    from cell.motion.timing import ptp
    from cell.motion.torch import WeldProcess

    sc = det.scenario
    arm = station.arm
    if arm is None:
        raise ScenarioError(f"scenario {sc.name!r} has no robot to weld with: set robot.urdf and robot.X_WR")
    assert det.scene is not None
    ss = det.scene.seam_scene
    tasks = seam_tasks([e for e in det.estimates if e.id not in skip], ss.weldmap, ss.joints, ss.table_z)
    obstacles = cell_obstacles(ss.weldmap, sc.X_WR, sc.table.center_m, sc.table.size_m)
    checker = CollisionChecker(arm.model, obstacles)
    progress(f"planning {len(tasks)} seams (IK, timing, collisions)")
    process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
    plan = plan_welds(arm.model, tasks, arm.q_home, process, obstacles, rng=sc.rng("plan"), checker=checker)
    pre = ptp(arm.q_scan if q_start is None else q_start, arm.q_home, arm.model.limits, dt=0.001)
    problems = []
    hit = checker.check_path(pre.q, pre.times)
    if hit is not None:
        problems.append(f"move from the arm's position to home collides: {hit.describe()}")
    progress("safety gate: limits at 1 kHz, collisions along the path, singularities, arc at exact stops")
    problems += [str(v) for v in find_violations(arm.model, plan, arm.q_home, checker=checker)]
    return plan, pre, tuple(problems)


def execute(station: Station, plan: WeldPlan, pre: Trajectory, *, progress: Progress = _quiet) -> Execution:
    """Drive the simulated arm: the move from the scan pose to home, then the welding program; arc where planned."""
    import numpy as np

    traj, arc = plan.joint_trajectory()
    times = np.concatenate([pre.times, traj.times[1:] + pre.duration])
    q = np.concatenate([pre.q, traj.q[1:]])
    arc_on = np.concatenate([np.zeros(len(pre.times), bool), arc[1:]])
    marks = [(0.0, "move scan -> home")] + [
        (pre.duration + seg.t0, f"{seg.kind} {seg.seam_id}".strip()) for seg in plan.segments
    ]
    progress(f"executing {plan.cycle_time + pre.duration:.1f} s of robot motion in the simulator")
    return station.sim.execute(times, q, arc_on, marks=marks, record_dt=0.01)


def _seam_welds(
    det: Detection, plan: WeldPlan | None, ex: Execution | None, pre_s: float, refused: str, sc: Scenario
) -> tuple[SeamWeld, ...]:
    """Per seam: welded (with its quality against the true seam) or the reason it was not."""
    import numpy as np

    from cell.geometry import transform_points
    from cell.motion.quality import weld_quality

    X_RW = invert(det.scenario.X_WR)
    out = []
    for est in det.estimates:
        if est.status is SeamStatus.NOT_VISIBLE:
            out.append(SeamWeld(est.id, False, False, est.reason))  # e.g. against the table: needs a flip
            continue
        if est.status is not SeamStatus.FOUND:
            out.append(SeamWeld(est.id, False, False, f"not located ({est.status.value}): {est.reason}"))
            continue
        doubtful = est.confidence < sc.rescan.weld_min_confidence
        if doubtful and ex is not None:
            why = f"low_confidence: {est.confidence:.2f} < {sc.rescan.weld_min_confidence:.2f} after the re-scan"
            out.append(SeamWeld(est.id, False, False, why))
            continue
        outcome = next((o for o in plan.seams if o.seam_id == est.id), None) if plan is not None else None
        if outcome is None or not outcome.feasible:
            reason = outcome.reason if outcome is not None else refused or "not planned"
            out.append(SeamWeld(est.id, False, False, reason))
            continue
        if ex is None or plan is None:
            note = f"; confidence {est.confidence:.2f}: would be re-scanned before welding" if doubtful else ""
            out.append(SeamWeld(est.id, True, False, (refused or "planned, not executed (preview)") + note))
            continue
        seg = next(g for g in plan.segments if g.arc_on and g.seam_id == est.id)
        t0, t1 = pre_s + seg.t0, pre_s + seg.t1
        k = np.flatnonzero((ex.times >= t0 - 1e-9) & (ex.times <= t1 + 1e-9))
        tcp_R = transform_points(X_RW, ex.tcp_W[k])
        out.append(SeamWeld(est.id, True, True, "", weld_quality(ex.times[k], tcp_R, *det.truths[est.id])))
    return tuple(out)


def weld(
    scenario: Scenario,
    method: str | None = None,
    *,
    noise: Literal["none", "realistic"] | None = None,
    rescan: Literal["none", "low", "all"] | None = None,
    execute_plan: bool = True,
    progress: Progress = _quiet,
    gui: bool = False,
) -> WeldRun:
    """The whole cell: capture, detect, re-scan up close, plan, gate and (unless ``execute_plan`` is False: a
    preview) weld. ``rescan`` overrides the scenario's ``rescan.mode``.

    A failure after detection (planning, the gate) does not lose the detection: it is returned in ``error`` with
    every seam's reason, so the report can still be written. A seam whose confidence stays below
    ``rescan.weld_min_confidence`` after the re-scan is not welded (``low_confidence``).
    """
    t_all = time.perf_counter()
    with Station(scenario.with_noise(noise) if noise else scenario, gui=gui) as station:
        sc = station.scenario
        det = detect(sc, method, progress=progress, station=station)
        first, rs = det, None
        timings = dict(det.timings)
        plan = pre = ex = None
        violations: tuple[str, ...] = ()
        error: CellError | None = None
        try:
            if det.error is not None:
                raise det.error
            mode = rescan or sc.rescan.mode
            if mode != "none" and station.arm is not None and execute_plan:
                rs, det = rescan_detection(station, det, mode, progress=progress)
                timings["rescan_s"] = rs.timings.get("rescan_s", 0.0)
            # A preview moves nothing, so it cannot re-scan: it plans doubtful seams too and says so.
            low = {
                e.id
                for e in det.estimates
                if e.status is SeamStatus.FOUND and e.confidence < sc.rescan.weld_min_confidence and execute_plan
            }
            t = time.perf_counter()
            q_start = rs.q_end if rs is not None else None
            plan, pre, violations = plan_for(station, det, skip=low, q_start=q_start, progress=progress)
            timings["plan_s"] = time.perf_counter() - t
            if violations:
                raise PlanError(f"the safety gate refused the plan: {violations[0]} (+{len(violations) - 1} more)")
            if execute_plan:
                t = time.perf_counter()
                ex = execute(station, plan, pre, progress=progress)
                timings["execute_s"] = time.perf_counter() - t
        except CellError as e:
            error = e
        refused = f"not executed: {error.message}" if error is not None else ""
        seams = _seam_welds(det, plan, ex, pre.duration if pre is not None else 0.0, refused, sc)
        paths = torch_paths(station, plan) if plan is not None else {}
        timings["total_s"] = time.perf_counter() - t_all
        return WeldRun(det, seams, plan, pre, ex, violations, error, timings, paths, station.arm, first, rs)


def rescan_detection(
    station: Station, det: Detection, mode: Literal["low", "all"], *, progress: Progress = _quiet
) -> tuple[Rescan, Detection]:
    """Re-scan the seams worth a closer look (``low``: below the confidence threshold or not found; ``all``: every
    visible seam) with the eye-in-hand camera and return the detection with the fused estimates.

    In ``low`` mode, a close-up that moves its seam by more than ``rescan.escalate_mm`` shows the fixed cameras
    cannot be trusted here (calibration off, a bumped camera): every other visible seam is re-scanned as well.
    """
    import math

    from cell.rescan import rescan_seams, rescanned, seams_to_rescan

    sc = det.scenario
    ids = seams_to_rescan(det, math.inf if mode == "all" else sc.rescan.confidence_threshold)
    progress(f"re-scanning {len(ids)} seams up close with the eye-in-hand camera")
    rs = rescan_seams(station, det, ids, progress=progress)
    after = rescanned(det, rs)
    shift_mm = max((_shift_m(r.before, r.closeup) * 1000.0 for r in rs.seams if r.used), default=0.0)
    rest = [i for i in seams_to_rescan(after, math.inf) if i not in ids]
    if mode == "low" and shift_mm > sc.rescan.escalate_mm and rest:
        progress(
            f"a close-up moved its seam {shift_mm:.2f} mm from the fixed cameras' estimate: re-scanning the other"
            f" {len(rest)} seams too"
        )
        more = rescan_seams(station, after, rest, progress=progress)
        after = rescanned(after, more)
        rs = replace(
            more,
            seams=rs.seams + more.seams,
            moves=rs.moves + more.moves,
            executions=rs.executions + more.executions,
            note=f"escalated: a close-up disagreed by {shift_mm:.2f} mm; {more.note}".rstrip("; "),
            timings={k: rs.timings.get(k, 0.0) + more.timings.get(k, 0.0) for k in {*rs.timings, *more.timings}},
        )
    return rs, after


def _shift_m(before: SeamEstimate, closeup: SeamEstimate | None) -> float:
    """Largest distance [m] between matching ends of two found estimates of one seam (0 when either is missing)."""
    import numpy as np

    if closeup is None or before.status is not SeamStatus.FOUND or closeup.status is not SeamStatus.FOUND:
        return 0.0
    a = np.stack([before.p_start, before.p_end])
    b = np.stack([closeup.p_start, closeup.p_end])
    return float(min(np.linalg.norm(a - b, axis=1).max(), np.linalg.norm(a - b[::-1], axis=1).max()))


def torch_paths(station: Station, plan: WeldPlan, step_s: float = 0.5) -> dict[str, FloatArray]:
    """Planned torch poses X_RT (n, 4, 4) along each weld, every ``step_s`` of arc time (for pictures and reports)."""
    import numpy as np

    if station.arm is None:
        return {}
    model = station.arm.model
    out = {}
    for seg in plan.segments:
        if seg.arc_on:
            tr = seg.trajectory
            k = np.unique(np.r_[np.searchsorted(tr.times, np.arange(0.0, tr.duration, step_s)), len(tr.times) - 1])
            out[seg.seam_id] = np.stack([model.fk(tr.q[i]) for i in k])
    return out
