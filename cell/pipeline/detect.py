"""Detection: capture -> perceive -> align the map -> locate every seam -> measure against the truth, if known."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Literal

import numpy as np

from cell.errors import AlignmentError, CellError, SensorError
from cell.geometry import FloatArray, invert
from cell.perception.align.fit import Alignment
from cell.perception.calibration import PoseUncertainty, curve_calibration_sigma, with_calibration
from cell.pipeline.evaluation import curve_truths, evaluate, truths
from cell.pipeline.geometry import open_cell
from cell.pipeline.progress import Progress, quiet
from cell.pipeline.records import Capture, Detection, Scene
from cell.scenario import Scenario
from cell.station import Station
from cell.types import Cloud, Reason, SeamEstimate, SeamScene, SeamStatus, WeldMap

if TYPE_CHECKING:
    from cell.perception.perceive import Perceived
    from cell.perception.table_check import SensorCheck

Seed = Callable[[Cloud, FloatArray], FloatArray]  # (dense cloud in R, nominal X_RM) -> X_RM to align from


@dataclass(frozen=True)
class AlignStart:
    """Where the map's alignment starts when the part is not where the scenario places it (a turned part): its
    believed pose X_RM (4, 4) and a search of the cloud near it (:data:`Seed`; None: from X_RM itself)."""

    X_RM: FloatArray
    seed: Seed | None = None


__all__ = [
    "AlignStart",
    "Progress",
    "build_scene",
    "capture",
    "detect",
    "evaluate",
    "locate",
    "quiet",
    "read_weldmap",
    "truths",
]


def read_weldmap(scenario: Scenario) -> WeldMap:
    """The scenario's welding map as drawn (frame M): the pipeline reads it, the station is built around it."""
    from cell.weldmap import read_map

    return read_map(scenario.map_path, units=scenario.map.units, layers=scenario.map.layers)


def capture(
    scenario: Scenario,
    *,
    gui: bool = False,
    progress: Progress = quiet,
    station: Station | None = None,
    weldmap: WeldMap | None = None,
) -> Capture:
    """Take one image with every camera of the scenario's cell (built here unless a running ``station`` is given).

    With a robot in the scenario, the arm first moves to its scan configuration: the eye-in-hand camera rides on
    it. The capture keeps the as-built parts (ground truth) for measuring, never for perception.
    """
    from cell.seams.joint import find_joints

    t0 = time.perf_counter()
    weldmap = weldmap if weldmap is not None else read_weldmap(scenario)
    if station is None:
        progress(f"building the cell of {scenario.name}")
        with open_cell(scenario, weldmap, gui=gui) as st:
            return capture(scenario, progress=progress, station=st, weldmap=weldmap)
    if station.source == "simulation":
        progress(f"rendering {len(scenario.cameras)} depth cameras ({scenario.noise} noise)")
    else:
        progress(f"reading {len(scenario.cameras)} depth cameras' images ({station.source})")
    from cell.perception.lens import undistort

    images = {name: undistort(image) for name, image in station.capture().items()}  # pinholes from here on
    return Capture(
        scenario, weldmap, find_joints(weldmap), station.truth(), images, time.perf_counter() - t0, station.source
    )


def table_z_R(scenario: Scenario) -> float:
    """Height [m] of the table top in the robot frame R."""
    return float((invert(scenario.X_WR) @ [0.0, 0.0, scenario.table.top_z, 1.0])[2])


def build_scene(
    cap: Capture,
    *,
    progress: Progress = quiet,
    X_RM_nominal: FloatArray | None = None,
    seed: Seed | None = None,
    keep: Callable[[Perceived], None] | None = None,
) -> Scene:
    """Perceive (deproject, splice, filter, downsample), align the map to the cloud, and pair seams with joints.

    X_RM_nominal : where the map is believed to lie (default: the scenario's ``map.X_WM``; the turned part's pose
    on its second side); seed : a search of the cloud near it for a start the ICP can converge from.
    keep : handed the perception once it is done, before an AlignmentError is raised (its clouds can be saved)."""
    from cell.perception import align_map, check_alignment
    from cell.perception.align.checks import cloud_tree_of
    from cell.perception.perceive import perceive_then

    sc = cap.scenario
    X_RM_believed = invert(sc.X_WR) @ sc.X_WM if X_RM_nominal is None else X_RM_nominal

    def aligned(cloud: Cloud, proceed: Callable[[], None]) -> tuple[Alignment, FloatArray, WeldMap, dict[str, str]]:
        """The map aligned to the registered cloud, and the checks of that fit (the stage after perception);
        ``proceed()`` between the steps (it stops a moot speculation)."""
        X_RM_start = X_RM_believed if seed is None else seed(cloud, X_RM_believed)
        weldmap_nominal_R = cap.weldmap.transformed(X_RM_start, "R")
        with ThreadPoolExecutor(max_workers=1) as beside:
            # The checks' KD-tree of the cloud is built on the other core while the alignment's ICP runs on one
            # (open3d's ICP and scipy's tree build both let go of the interpreter lock); it is the tree the checks
            # would build.
            tree = beside.submit(cloud_tree_of, cloud) if len(cloud) else None
            alignment = align_map(weldmap_nominal_R, cloud, sc.perception, proceed)
            proceed()
            X_RM = alignment.X_RR_corr @ X_RM_start
            weldmap_R = cap.weldmap.transformed(X_RM, "R")
            # A fit that a near-symmetry explains as well (a ladder one rung off) or a map half off the cloud is
            # refused; parts that are simply not there are named, and their seams are never searched.
            # Each part is judged by the top a camera has in sight (not what another part shadows from all).
            eyes_R = np.array([(invert(sc.X_WR) @ image.X_WC)[:3, 3] for image in cap.images.values()])
            checks_tree = tree.result() if tree else None
            missing = check_alignment(weldmap_R, cloud, alignment, sc.perception, checks_tree, eyes_R.reshape(-1, 3))
        return alignment, X_RM, weldmap_R, missing

    def aligned_or_error(
        cloud: Cloud, proceed: Callable[[], None]
    ) -> tuple[Alignment, FloatArray, WeldMap, dict[str, str]] | AlignmentError:
        try:
            return aligned(cloud, proceed)
        except AlignmentError as e:  # raised below, once the perception is kept
            return e

    progress("splicing point clouds and aligning the welding map to them")
    # Alignment and our locator read every camera's registered points (the unmerged cloud): the paper's merge keeps
    # one camera per region and throws away good data; the paper's method keeps its merged, downsampled cloud. The
    # alignment starts beside the splice (perceive_then); the stage times split the wall where the cloud was ready.
    checks = sensor_checks(cap, progress)
    done = perceive_then(
        cap.images, sc.X_WR, sc.perception, sc.perception.health, aligned_or_error, pose_uncertainties(sc), checks
    )
    if keep is not None:
        keep(done.perceived)
    if isinstance(done.answer, AlignmentError):
        raise done.answer
    perceived, (alignment, X_RM, weldmap_R, missing) = done.perceived, done.answer
    timings = {"perceive_s": done.cloud_s, "align_s": done.answer_s - done.cloud_s}

    seam_scene = SeamScene(
        voxel=lambda: perceived.downsampled,  # the paper's merged cloud, made when a locator reads it
        dense=perceived.registered,
        weldmap=weldmap_R,
        joints=cap.joints,
        table_z=table_z_R(sc),
        dense_voxels=perceived.registered_voxels,
        eyes_R=perceived.origins_R,
    )
    return Scene(seam_scene, perceived, alignment, X_RM, timings, missing)


def locate(scene: Scene, scenario: Scenario, method: str, *, progress: Progress = quiet) -> tuple[SeamEstimate, ...]:
    """Run one locator over every seam of the aligned map; seams no camera can see are reported, not searched."""
    from cell.perception import screen
    from cell.seams.base import locate_all
    from cell.seams.checks import check_ends
    from cell.seams.joint import weld_faces
    from cell.seams.registry import make_locator, part_tolerance_m

    ss = scene.seam_scene
    locator = make_locator(method, scenario)
    rng = scenario.rng(f"locator/{method}")
    progress(f"locating {len(ss.weldmap.seams)} seams ({method})")
    out = locate_all(locator, ss, rng)
    searched = [e.id for e in out if e.status is not SeamStatus.NOT_VISIBLE]
    # Ends inside another body, off their joint's faces or making a length the map does not draw: cut or replaced.
    out = check_ends(ss.weldmap, ss.joints, out, part_tolerance_m(scenario, method))
    # Missing parts, occluders (points the map does not explain) and near-zero confidence: never a guess.
    out = screen(ss, out, scene.missing, scenario.perception.screen)
    # A seam resting on one camera carries that camera's calibration error (the locator's sigma cannot see it).
    p = scene.perceived
    faces = {i: weld_faces(ss.weldmap, ss.joints[i]) for i in searched if i in ss.joints}
    return with_calibration(
        out, p.registered, p.origins_R, pose_uncertainties(scenario), p.spliced.registrations, faces
    )


def sensor_checks(cap: Capture, progress: Progress = quiet) -> dict[str, SensorCheck]:
    """Each camera's depth scale and focal length checked on the table in its own image (a flagged one said)."""
    from cell.perception.table_check import check_cameras

    sc = cap.scenario
    if not sc.perception.health.table_check:
        return {}
    out = check_cameras(cap.images, sc, cap.weldmap.transformed(sc.X_WM, "W"), pose_uncertainties(sc))
    for name, check in out.items():
        if check.flags:
            progress(f"warning: {name}: {check.reason()}")
    return out


def pose_uncertainties(scenario: Scenario) -> dict[str, PoseUncertainty]:
    """Camera name -> how well its pose is known (the scenario's ``cameras.<name>.calibration``), in SI units."""
    return {
        name: PoseUncertainty(cam.calibration.translation_mm * 1e-3, math.radians(cam.calibration.rotation_deg))
        for name, cam in scenario.cameras.items()
    }


def detect(
    scenario: Scenario,
    method: str | None = None,
    *,
    noise: Literal["none", "realistic"] | None = None,
    progress: Progress = quiet,
    gui: bool = False,
    station: Station | None = None,
    weldmap: WeldMap | None = None,
    X_RM_nominal: FloatArray | None = None,
    seed: Seed | None = None,
) -> Detection:
    """Capture, perceive, align and locate every seam of the scenario's welding map; measure against truth.

    station, weldmap : a running cell and the map it was built around (both built here when not given).
    X_RM_nominal, seed : the map's believed pose and a search near it (:func:`build_scene`).
    """
    from cell.seams.curved.results import curve_results
    from cell.seams.registry import with_method

    if noise is not None:
        scenario = scenario.with_noise(noise)
    scenario = with_method(scenario, method)  # a --method runs with its spec's defaults, and the report says so
    method = scenario.locator.method
    t_all = time.perf_counter()
    cap = capture(scenario, gui=gui, progress=progress, station=station, weldmap=weldmap)
    kept: list[Perceived] = []
    try:
        scene = build_scene(cap, progress=progress, X_RM_nominal=X_RM_nominal, seed=seed, keep=kept.append)
    except (SensorError, AlignmentError) as e:
        # No seam can be searched, but every seam is still reported, with the reason; nothing is invented.
        progress(f"no seam search: {e.message}")
        failed = _failed_detection(cap, method, e, time.perf_counter() - t_all, X_RM_nominal)
        return replace(failed, perceived=kept[0] if kept else None)
    estimates = locate(scene, scenario, method, progress=progress)
    weldmap_R = scene.seam_scene.weldmap
    truth = truths(cap, weldmap_R)
    curve_truth = curve_truths(cap)
    p, u = scene.perceived, pose_uncertainties(scenario)  # a camera's pose error moves a curve as a straight seam
    cal = lambda q: curve_calibration_sigma(p.registered, q, p.origins_R, u, p.spliced.registrations)  # noqa: E731
    curves = curve_results(method, scene.seam_scene, curve_truth, cal)
    metrics, summary = evaluate(estimates, truth)
    timings = {"capture_s": cap.seconds, **scene.timings}
    timings["locate_s"] = sum(e.time_s for e in estimates) + sum(e.time_s for e in curves[0])
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
        joints=cap.joints,
        source=cap.source,
        curve_truths=curve_truth,
        curve_estimates=curves[0],
        curve_metrics=curves[1],
    )


def _failed_detection(
    cap: Capture, method: str, error: CellError, seconds: float, X_RM: FloatArray | None = None
) -> Detection:
    """A detection whose perception or alignment failed: every seam NOT_FOUND (underside ones NOT_VISIBLE, which
    the drawing alone tells) with the reason, against the nominal map."""
    from cell.seams.curved.results import not_searched
    from cell.seams.visibility import visibility

    sc = cap.scenario
    weldmap_R = cap.weldmap.transformed(invert(sc.X_WR) @ sc.X_WM if X_RM is None else X_RM, "R")
    joints = cap.joints
    table_z = table_z_R(sc)
    estimates = []
    for seam in weldmap_R.seams:
        visible, why = visibility(weldmap_R, joints[seam.id], table_z)
        if visible:
            estimates.append(
                SeamEstimate(seam.id, SeamStatus.NOT_FOUND, f"no seam search: {error.message}", code=Reason.NO_SEARCH)
            )
        else:
            estimates.append(SeamEstimate(seam.id, SeamStatus.NOT_VISIBLE, why, code=Reason.UNDERSIDE))
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
        joints=cap.joints,
        source=cap.source,
        curve_truths=curve_truths(cap),
        curve_estimates=not_searched(weldmap_R, error.message),
    )
