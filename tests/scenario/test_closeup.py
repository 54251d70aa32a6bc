"""Close-up re-scan on fence1 and on fixed cameras off their calibration: the close-up improves a seam and returns
the arm; a close-up that sees nothing keeps the first estimate; the arm's camera undoes the fixed cameras' error.

fence1's detection is the session's (tests/conftest.py); each test drives a station of its own, so no test sees
the arm or the camera noise another one left behind.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from cell import pipeline
from cell.config.rescan import RescanOptions
from cell.pipeline import rescan_seams, rescanned
from cell.pipeline.geometry import open_cell
from cell.seams.metrics import segment_errors
from cell.station import SimStation
from cell.types import SeamStatus


def test_rescan_improves_the_least_confident_seam_and_returns_the_arm(
    fence1_detection: pipeline.Detection, fence1_station: SimStation
) -> None:
    det, station = fence1_detection, fence1_station
    worst = min((e for e in det.estimates if e.status is SeamStatus.FOUND), key=lambda e: e.confidence)
    rs = rescan_seams(station, det, [worst.id])
    (r,) = rs.seams
    assert r.reason == "" and r.viewpoint is not None and r.closeup is not None and r.weight > 0.5
    truth = det.truths[worst.id]
    lat0 = segment_errors(r.before.p_start, r.before.p_end, *truth)[2]
    _, end1, lat1, _ = segment_errors(r.fused.p_start, r.fused.p_end, *truth)
    # [mm] measured: lateral 0.094 before, 0.033 after (the close-up weighs over 0.95); 0.070 and 0.010 before the
    # arm model grew to the real arm's size (it hides more of the part from the fixed cameras)
    assert lat1 < 0.5 * lat0 and lat1 < 0.05 and end1 < 0.05 and r.weight > 0.95
    assert r.motion_s > 0.0 and len(rs.executions) == 2  # to the view, and back
    assert station.arm is not None
    assert rs.returned and np.allclose(station.joint_state(), station.arm.q_scan, atol=1e-9)
    after = rescanned(det, rs)
    assert after.metrics[worst.id].lateral_mm == pytest.approx(lat1)
    assert [e.id for e in after.estimates] == [e.id for e in det.estimates]


def test_a_closeup_that_sees_nothing_keeps_the_first_estimate(
    fence1_detection: pipeline.Detection, fence1_station: SimStation
) -> None:
    det, station = fence1_detection, fence1_station
    seam = next(e for e in det.estimates if e.status is SeamStatus.FOUND)
    rs = rescan_seams(station, det, [seam.id], options=RescanOptions(min_points=10**8))
    (r,) = rs.seams
    assert r.reason.startswith("nothing seen") and r.fused is r.before and r.weight == 0.0
    assert r.closeup is None and 0 < r.points < 10**8
    assert next(e for e in rs.estimates if e.id == seam.id) is seam


def test_rescan_undoes_the_fixed_cameras_calibration_error(detected: Callable[..., pipeline.Detection]) -> None:
    """Fixed cameras off by 1 mm / 0.1 deg: the arm's camera (posed by the robot's kinematics) brings every seam
    back under 0.5 mm lateral (issue acceptance), and improves the mean. The detection is the session's
    (``detected``, which test_splice_refusals.py reads too); the close-ups run on a station of the test's own, left
    as the detection left its station (every camera one image on, as ``fence1_station`` is)."""
    det = detected("faults/extrinsics-fixed-off")
    scn = det.scenario
    with open_cell(scn, pipeline.read_weldmap(scn)) as station:
        station.capture()
        ids = [e.id for e in det.estimates if e.status is SeamStatus.FOUND]
        after = rescanned(det, rescan_seams(station, det, ids))
    assert after.summary.found == 12
    assert max(m.lateral_mm for m in after.metrics.values()) < 0.5  # the acceptance figure, every seam
    assert after.summary.lateral_mean_mm < 0.03  # measured 0.014 mm (0.089 mm before the re-scan)
    assert after.summary.lateral_mean_mm < det.summary.lateral_mean_mm
