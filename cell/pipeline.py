"""The only place that knows the order of the stages: capture -> perceive -> align map -> locate -> evaluate.

Each stage is a function taking values and returning values; this module wires them and times them. The CLI is a thin
layer over :func:`detect` (and, for the bench, over :func:`capture`, :func:`build_scene` and :func:`locate`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

from cell.geometry import FloatArray, invert
from cell.scenario import Scenario
from cell.seams.base import SeamScene
from cell.seams.metrics import MetricsSummary, SeamMetrics
from cell.types import DepthImage, Part, SeamEstimate, SeamStatus, WeldMap

if TYPE_CHECKING:  # heavy imports stay inside the stages that need them
    from cell.perception import Alignment, Perceived

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

    @property
    def complete(self) -> bool:
        """Every seam that can be seen was found."""
        return all(e.status is not SeamStatus.NOT_FOUND for e in self.estimates)


def capture(scenario: Scenario, *, gui: bool = False, progress: Progress = _quiet) -> Capture:
    """Build the simulated cell from the scenario and take one image with every camera."""
    from cell.asbuilt import as_built_parts
    from cell.sim.cell import SimCell
    from cell.weldmap import read_map

    t0 = time.perf_counter()
    progress(f"reading welding map {scenario.map_path.name}")
    weldmap = read_map(scenario.map_path, units=scenario.map.units)
    parts_W = as_built_parts(weldmap, scenario)
    progress(f"rendering {len(scenario.cameras)} depth cameras ({scenario.noise} noise)")
    with SimCell(scenario, parts_W, gui=gui) as sim:
        images = sim.capture_all()
    return Capture(scenario, weldmap, parts_W, images, time.perf_counter() - t0)


def build_scene(cap: Capture, *, progress: Progress = _quiet) -> Scene:
    """Perceive (deproject, splice, filter, downsample), align the map to the cloud, and pair seams with joints."""
    from cell.perception import align_map, perceive
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
    alignment = align_map(weldmap_nominal_R, perceived.dense, sc.perception)
    X_RM = alignment.X_RR_corr @ X_RM_nominal
    weldmap_R = cap.weldmap.transformed(X_RM, "R")
    joints = find_joints(weldmap_R)
    timings["align_s"] = time.perf_counter() - t

    table_z_R = float((invert(sc.X_WR) @ [0.0, 0.0, sc.table.top_z, 1.0])[2])
    seam_scene = SeamScene(
        cloud=perceived.downsampled,
        dense=perceived.dense,
        weldmap=weldmap_R,
        joints=joints,
        table_z=table_z_R,
    )
    return Scene(seam_scene, perceived, alignment, X_RM, timings)


def locate(
    scene: Scene, scenario: Scenario, method: str, *, progress: Progress = _quiet
) -> tuple[SeamEstimate, ...]:
    """Run one locator over every seam of the aligned map; seams no camera can see are reported, not searched."""
    from cell.seams.registry import make_locator
    from cell.seams.visibility import visibility

    ss = scene.seam_scene
    locator = make_locator(method, scenario)
    rng = scenario.rng(f"locator/{method}")
    progress(f"locating {len(ss.weldmap.seams)} seams ({method})")
    out = []
    for seam in ss.weldmap.seams:
        visible, reason = visibility(ss.weldmap, ss.joints[seam.id], ss.table_z)
        if not visible:
            out.append(SeamEstimate(seam.id, SeamStatus.NOT_VISIBLE, reason))
            continue
        t = time.perf_counter()
        est = locator.locate(ss, seam, rng)
        dt = time.perf_counter() - t
        out.append(
            SeamEstimate(est.id, est.status, est.reason, est.p_start, est.p_end, est.confidence, time_s=dt)
        )
    return tuple(out)


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
) -> Detection:
    """Capture, perceive, align and locate every seam of the scenario's welding map; measure against truth."""
    if noise is not None:
        scenario = scenario.with_noise(noise)
    method = method or scenario.locator.method
    t_all = time.perf_counter()
    cap = capture(scenario, gui=gui, progress=progress)
    scene = build_scene(cap, progress=progress)
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
        lost_cameras=scene.perceived.lost,
        scene=scene,
    )
