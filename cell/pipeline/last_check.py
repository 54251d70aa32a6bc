"""The last check before the arc, in the run: every found seam about to be welded is held against the aligned map
(:func:`cell.seams.checks.last_check.last_check`, with its budget derived here from the scenario, :func:`check_budget`);
a seam that fails is re-scanned up close (the re-scan loop of :mod:`cell.pipeline.rescan`) and checked again, and
one that still fails is not welded (``last_check``, with the test it failed)."""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from dataclasses import replace

import numpy as np

from cell.errors import CellError
from cell.geometry import transform_points
from cell.pipeline.detect import Progress, quiet
from cell.pipeline.geometry import MotionScene
from cell.pipeline.records import Detection
from cell.pipeline.rescan import rescan_seams, rescanned
from cell.scenario import Scenario
from cell.seams.checks import Budget, budget, last_check
from cell.station import Station
from cell.types import CheckFail, SeamEstimate, SeamStatus
from cell.types.rescan import Rescan

MAP_TOLERANCE_M = 0.006  # how far the as-built faces and ends may lie from the aligned map, when the locator's
# options do not say (``locator.options.map_tolerance_m`` of ours)


def check_budget(sc: Scenario, est: SeamEstimate) -> Budget:
    """The last check's budget of one found estimate, from the scenario alone: the build tolerance the locator
    is told (``locator.options.map_tolerance_m``), the largest stated calibration of a fixed camera at its range to
    the seam (``cameras.<name>.calibration``: translation plus rotation times range), and the estimate's sigma
    across the seam and its ends' along it."""
    tol = float(getattr(sc.locator.options, "map_tolerance_m", MAP_TOLERANCE_M))
    mid_W = transform_points(sc.X_WR, 0.5 * (est.p_start + est.p_end))
    calibration = max(
        (
            c.calibration.translation_mm * 1e-3
            + math.radians(c.calibration.rotation_deg) * float(np.linalg.norm(np.asarray(c.eye_m) - mid_W))
            for c in sc.cameras.values()
            if c.mount == "fixed"
        ),
        default=0.0,
    )
    return budget(tol, calibration, est.sigma_m, est.end_sigma_m)


def failing(det: Detection, ids: Collection[str] | None = None) -> dict[str, CheckFail]:
    """Seam id -> the test it fails, for the found seams of ``det`` (those of ``ids`` only, when given)."""
    if det.scene is None:
        return {}
    ss = det.scene.seam_scene
    out = {}
    for est in det.estimates:
        if est.status is not SeamStatus.FOUND or (ids is not None and est.id not in ids):
            continue
        fail = last_check(
            est, ss.weldmap.seam(est.id), ss.joints.get(est.id), ss.weldmap.parts, check_budget(det.scenario, est)
        )
        if fail is not None:
            out[est.id] = fail
    return out


def last_checked(
    station: Station,
    det: Detection,
    *,
    skip: Collection[str] = (),
    motion: MotionScene | None = None,
    progress: Progress = quiet,
) -> tuple[Detection, Rescan | None, dict[str, CheckFail]]:
    """The last check of the found seams of ``det`` (but ``skip``): those that fail are re-scanned up close and
    checked again. Returns the detection after it, the re-scan (None when nothing failed) and the seams that
    still fail, each with its test. A seam that cannot be re-scanned (no arm, no eye-in-hand camera) keeps its
    first failure."""
    ids = [e.id for e in det.estimates if e.status is SeamStatus.FOUND and e.id not in skip]
    fails = failing(det, ids)
    if not fails:
        return det, None, {}
    said = "; ".join(f"{sid}: {f.describe()}" for sid, f in fails.items())
    progress(f"last check before the arc: {len(fails)} seams cannot be where they were located ({said}): re-scanning")
    try:
        rs = rescan_seams(station, det, list(fails), motion=motion, progress=progress)
    except (CellError, KeyError, ValueError) as exc:
        progress(f"last check: no close-up re-scan ({exc}): refusing them")
        return det, None, fails
    after = rescanned(det, rs)
    return after, rs, failing(after, list(fails))


def joined(first: Rescan | None, more: Rescan | None) -> Rescan | None:
    """One re-scan record of the weld's re-scan and the last check's after it (the arm is where ``more`` left it)."""
    if first is None or more is None:
        return more or first
    timings: Mapping[str, float] = {
        k: first.timings.get(k, 0.0) + more.timings.get(k, 0.0) for k in {*first.timings, *more.timings}
    }
    return replace(
        more,
        seams=first.seams + more.seams,
        curves=first.curves + more.curves,
        moves=first.moves + more.moves,
        executions=first.executions + more.executions,
        timings=dict(timings),
        escalated_mm=first.escalated_mm,
        note="; ".join(n for n in (first.note, more.note) if n),
    )
