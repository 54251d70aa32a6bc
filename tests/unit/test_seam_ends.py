"""The uncertainty of a seam's ends along it: each end source's sigma, the ends checked against the aligned map
(length, other bodies), the fusion and the calibration term per end, and ours on skewed joints (a mitred brace at
20-70 deg to what it joins: tests/unit/skewed_joint.py)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from skewed_joint import scene as skewed_scene
from synthetic_joint import CASES, JOINTS, NOMINAL, TOP, make_scene, square_tube

from cell.config.seams import PART_TOLERANCE_M
from cell.geometry import make_pose
from cell.perception.calibration import PoseUncertainty, closeup_sigma
from cell.rescan.fusion import fuse, fuse_along
from cell.seams.checks import check_ends
from cell.seams.metrics import end_errors_along
from cell.seams.ours import OursLocator
from cell.seams.sigma import (
    OURS_END_FLOOR_M,
    PAPER_SIGMA_UNSEEN_M,
    PAPER_START_SIGMA_M,
    RANSAC_END_SIGMA_M,
    SE_INFLATION,
    drawn_end_sigma,
    length_tolerance_m,
    ours_end_sigma,
    paper_end_sigmas,
)
from cell.types import Box, EndSource, MapSeam, Part, Reason, SeamEstimate, SeamStatus, WeldMap

# -- each end source's sigma ----------------------------------------------------------------------------------


def test_each_end_source_has_its_sigma() -> None:
    # ours: its standard error (widened) with the floor of its source in quadrature, a bias no fit sees added, not
    # widened; the drawn end the part tolerance.
    for source in (EndSource.EDGE, EndSource.FACE_END, EndSource.OTHER_PART):
        floor = OURS_END_FLOOR_M[source]
        assert ours_end_sigma(0.0, source) == pytest.approx(floor)
        assert ours_end_sigma(3e-4, source) == pytest.approx(math.hypot(SE_INFLATION * 3e-4, floor))
        assert ours_end_sigma(3e-4, source, bias_m=2e-4) == pytest.approx(math.hypot(SE_INFLATION * 3e-4, floor, 2e-4))
    assert drawn_end_sigma() == pytest.approx(PART_TOLERANCE_M)
    assert drawn_end_sigma(PART_TOLERANCE_M, 0.5) > drawn_end_sigma(PART_TOLERANCE_M, 0.05) > PART_TOLERANCE_M
    assert length_tolerance_m(PART_TOLERANCE_M, 0.4) == pytest.approx(PART_TOLERANCE_M + 0.02)
    # The paper's start read on faces; its end the start plus the map's vector: wider, and the drawn length's too.
    start, end = paper_end_sigmas(1.0, 0.1)
    assert start == PAPER_START_SIGMA_M and end == pytest.approx(math.hypot(start, drawn_end_sigma(length_m=0.1)))
    assert paper_end_sigmas(0.5, 0.1)[0] == PAPER_SIGMA_UNSEEN_M
    assert RANSAC_END_SIGMA_M >= 0.01  # its ends are where a 1 cm voxel cloud's inliers stop: wide


def test_ours_reports_each_end_with_its_source_and_a_sigma_that_covers_it() -> None:
    X, opts = CASES["axis-aligned"]
    sc, truth = make_scene(X, opts)
    est = OursLocator().locate(sc, sc.weldmap.seam(TOP), np.random.default_rng(0))
    assert est.status is SeamStatus.FOUND
    assert all(isinstance(k, EndSource) and k is not EndSource.DRAWN for k in est.end_source)
    errors = np.abs(end_errors_along(est.p_start, est.p_end, *truth[TOP]))
    sigmas = np.array(est.end_sigma_m) * 1000.0
    assert np.all(np.isfinite(sigmas)) and np.all(sigmas < 1.0)
    assert np.all(errors <= 2.5 * sigmas), (errors, sigmas)


def test_end_errors_along_are_signed_past_and_short() -> None:
    t0, t1 = np.zeros(3), np.array([0.1, 0.0, 0.0])
    past_start, short_end = np.array([-0.002, 0.0, 0.0]), np.array([0.097, 0.0, 0.0])
    assert end_errors_along(past_start, short_end, t0, t1) == pytest.approx((2.0, -3.0))
    assert end_errors_along(short_end, past_start, t0, t1) == pytest.approx((2.0, -3.0))  # reported reversed


# -- the ends against the aligned map --------------------------------------------------------------------------


def _map(*extra: Part) -> tuple[WeldMap, MapSeam]:
    seam = MapSeam(TOP, np.array([-0.04, 0.0, 0.08]), np.array([0.04, 0.0, 0.08]))
    parts = (*(Part(k, b) for k, b in NOMINAL.items()), *extra)
    return WeldMap(parts, (seam,), "mm", "synthetic", frame="R"), seam


def _found(a: np.ndarray, b: np.ndarray, sigma_end: float = 2e-4) -> SeamEstimate:
    ends = (EndSource.EDGE, EndSource.FACE_END)
    return SeamEstimate(
        TOP, SeamStatus.FOUND, "", a, b, 0.9, sigma_m=1e-4, end_sigma_m=(sigma_end,) * 2, end_source=ends
    )


def test_a_seam_within_the_drawn_length_is_kept_as_located() -> None:
    weldmap, seam = _map()
    est = _found(
        seam.p_start + np.array([0.001, 0.0, 0.0005]), seam.p_end + np.array([0.003, 0.0, 0.0005])
    )  # 2 mm longer
    assert check_ends(weldmap, JOINTS, [est], PART_TOLERANCE_M)[0] is est


def test_a_seam_running_past_its_joint_gets_that_end_from_the_map_on_the_located_line() -> None:
    weldmap, seam = _map()
    lift = np.array([0.0, 0.0003, 0.0005])  # the located line lies off the map's: it must stay where it was found
    est = _found(seam.p_start + lift, seam.p_end + lift + np.array([0.0186, 0.0, 0.0]))  # a brace's 18.6 mm run on
    out = check_ends(weldmap, JOINTS, [est], PART_TOLERANCE_M)[0]
    assert out.status is SeamStatus.FOUND
    assert out.end_source == (EndSource.EDGE, EndSource.DRAWN)
    assert out.end_sigma_m[1] == pytest.approx(drawn_end_sigma(PART_TOLERANCE_M, seam.length))
    np.testing.assert_allclose(out.p_start, est.p_start)
    np.testing.assert_allclose(out.p_end, seam.p_end + lift, atol=1e-9)  # the map's end, on the located line
    assert "end from the map" in out.reason


def test_a_seam_far_from_its_drawn_length_is_not_this_joint() -> None:
    weldmap, seam = _map()
    est = _found(seam.p_start, seam.p_start + 0.3 * (seam.p_end - seam.p_start))
    out = check_ends(weldmap, JOINTS, [est], PART_TOLERANCE_M)[0]
    assert out.status is SeamStatus.NOT_FOUND and out.code is Reason.LENGTH_MISMATCH


@pytest.mark.parametrize("kind", ["box", "tube", "tube_on_face"])
def test_an_end_never_lies_inside_a_third_body(kind: str) -> None:
    # A third part stands where the seam ends: a rail across it, or a tube whose bore the located end ran into
    # (through its 2.6 mm wall). The end is cut at its face, and said to come from another part. ``tube_on_face``:
    # the tube stands on B's face, level with the seam's line (which only grazes its wall): the bead's walk, lifted
    # out of the fillet corner, enters it (the line's alone left the end in the bore).
    if kind == "box":
        # its face at x = 0.04, set 1 mm into B's face (the seam's line lies on that face)
        third = Box(make_pose(p=(0.07, -0.029, 0.08)), np.array([0.06, 0.06, 0.04]))
    elif kind == "tube":
        third = square_tube(np.array([0.07, -0.029, 0.0]), 0.06, 0.0026, 0.12)  # its outer wall at x = 0.04
    else:
        third = square_tube(np.array([0.07, -0.030, 0.0]), 0.06, 0.0026, 0.12)  # its wall ends on B's face
    weldmap, seam = _map(Part("THIRD", third))
    est = _found(seam.p_start, seam.p_end + np.array([0.0088 + 0.0026, 0.0, 0.0]))  # 8.8 mm into the bore
    out = check_ends(weldmap, JOINTS, [est], PART_TOLERANCE_M)[0]
    assert out.status is SeamStatus.FOUND
    assert not Part("THIRD", third).contains(out.p_end[None], -1e-4)[0]
    assert out.p_end[0] == pytest.approx(0.04, abs=4e-4)  # at the face it meets
    assert out.end_source[1] is EndSource.OTHER_PART
    # moved 11 mm, far more than its sigma: only the map's body places it now
    assert out.end_sigma_m[1] >= PART_TOLERANCE_M
    # Nothing on the walk from the middle to either end lies inside it.
    u = np.linspace(0.0, 1.0, 400)[:, None]
    assert not np.any(Part("THIRD", third).contains(out.p_start + u * (out.p_end - out.p_start), -4e-4))


# -- the fusion and the calibration term, per end ----------------------------------------------------------------


def test_each_end_fuses_by_its_own_sigma_and_the_line_across_by_its_own() -> None:
    a, b = np.zeros(3), np.array([0.1, 0.0, 0.0])
    first = SeamEstimate(
        "s",
        SeamStatus.FOUND,
        "",
        a,
        b,
        0.9,
        sigma_m=2e-4,
        end_sigma_m=(6e-3, 1e-4),
        end_source=(EndSource.DRAWN, EndSource.EDGE),
    )
    close = SeamEstimate(
        "s",
        SeamStatus.FOUND,
        "",
        b + np.array([0.0, 2e-4, 0.0]),
        a + np.array([0.005, 2e-4, 0.0]),
        0.9,
        sigma_m=2e-4,
        end_sigma_m=(1e-3, 1e-4),
        end_source=(EndSource.EDGE, EndSource.FACE_END),
    )  # reported reversed
    fused, w = fuse(first, close, first.sigma_m, close.sigma_m, 1e-3)
    assert w == pytest.approx(0.5)
    np.testing.assert_allclose(fused.p_start[1:], [1e-4, 0.0], atol=1e-12)  # across: the plain average
    # the start: the close-up's (sigma 0.1 mm) against a drawn one (6 mm); the end: the first's 0.1 mm against 1 mm
    assert fused.p_start[0] == pytest.approx(fuse_along(0.0, 6e-3, 0.005, 1e-4)[0], abs=1e-9)
    assert fused.p_start[0] == pytest.approx(0.005, abs=2e-6)
    assert fused.p_end[0] == pytest.approx(0.1, abs=1e-9)
    assert fused.end_sigma_m[0] == pytest.approx(fuse_along(0.0, 6e-3, 0.0, 1e-4)[1])
    assert fused.end_sigma_m[1] == pytest.approx(fuse_along(0.0, 1e-4, 0.0, 1e-3)[1])
    assert fused.end_source == (EndSource.FACE_END, EndSource.EDGE)  # each from the surer estimate


def test_ends_that_disagree_are_not_averaged_into_a_small_sigma() -> None:
    # within 3 combined sigmas: inverse variance, the fused sigma smaller than either
    x, s = fuse_along(0.0, 2e-4, 3e-4, 2e-4)
    assert x == pytest.approx(1.5e-4) and s == pytest.approx(2e-4 / math.sqrt(2.0))
    # a first end confidently 30 mm out against a close-up: the close-up's place, as uncertain as half the gap
    x, s = fuse_along(0.030, 1e-4, 0.0, 2e-4)
    assert x == 0.0 and s == pytest.approx(0.015)
    # a small disagreement just past the test: the sigma covers it, the place is the close-up's
    x, s = fuse_along(0.0, 1e-4, 1e-3, 1e-4)
    assert x == pytest.approx(1e-3) and s == pytest.approx(5e-4)


def test_the_calibration_term_widens_the_ends_too() -> None:
    est = SeamEstimate(
        "s", SeamStatus.FOUND, "", np.zeros(3), np.array([0.1, 0.0, 0.0]), 0.9, sigma_m=1e-4, end_sigma_m=(1e-4, 2e-4)
    )
    out = closeup_sigma(est, np.array([0.0, 0.0, 0.4]), PoseUncertainty(0.001, 0.0))
    cal = 0.001 / math.sqrt(3.0)
    assert out.sigma_m == pytest.approx(math.hypot(1e-4, cal))
    assert out.end_sigma_m == pytest.approx((math.hypot(1e-4, cal), math.hypot(2e-4, cal)))


# -- ours on skewed joints ------------------------------------------------------------------------------------


@pytest.mark.parametrize("angle_deg", [20.0, 44.0, 70.0])
@pytest.mark.parametrize("gap_m", [0.0005, 0.002])
def test_a_skewed_brace_ends_within_its_sigmas_and_never_runs_past_the_joint(angle_deg: float, gap_m: float) -> None:
    sc, truth = skewed_scene(angle_deg, gap_m)
    seam = sc.weldmap.seams[0]
    est = OursLocator().locate(sc, seam, np.random.default_rng(0))
    est = check_ends(sc.weldmap, sc.joints, [est], PART_TOLERANCE_M)[0]
    assert est.status is SeamStatus.FOUND
    assert EndSource.DRAWN not in est.end_source  # both ends seen, none taken from the map
    errors = np.array(end_errors_along(est.p_start, est.p_end, *truth))  # [mm], positive past the joint's end
    sigmas = np.array(est.end_sigma_m) * 1000.0
    assert np.all(np.abs(errors) <= 2.5 * sigmas), (errors, sigmas)
    assert np.all(errors < 1.0)  # never a bead more than the end tolerance past the joint
    lateral = max(float(np.linalg.norm(np.cross(p - truth[0], truth[1] - truth[0]))) for p in (est.p_start, est.p_end))
    assert lateral / float(np.linalg.norm(truth[1] - truth[0])) < 5e-4


def test_a_located_end_replaced_keeps_the_estimate_frozen() -> None:
    weldmap, seam = _map()
    est = _found(seam.p_start, seam.p_end + np.array([0.02, 0.0, 0.0]))
    out = check_ends(weldmap, JOINTS, [est], PART_TOLERANCE_M)[0]
    assert not out.p_end.flags.writeable and replace(out).end_source == out.end_source


# -- the weld gate ------------------------------------------------------------------------------------------------


def test_the_gate_refuses_a_seam_whose_end_bound_stays_over_the_end_tolerance() -> None:
    from types import SimpleNamespace
    from typing import Any

    from cell.pipeline import Detection, evaluate
    from cell.pipeline.outcomes import doubt, end_doubt, seam_welds
    from cell.types.run import WeldReason

    rescan = SimpleNamespace(
        max_sigma_m=0.5e-3 / 3.0,
        bound_sigmas=3.0,
        weld_tolerance_mm=0.5,
        weld_min_confidence=0.3,
        max_end_sigma_m=1e-3 / 3.0,
        end_tolerance_mm=1.0,
    )
    sc: Any = SimpleNamespace(rescan=rescan, X_WR=np.eye(4))
    a, b = np.zeros(3), np.array([0.1, 0.0, 0.0])
    sure = SeamEstimate("sure", SeamStatus.FOUND, "", a, b, 0.9, sigma_m=1e-4, end_sigma_m=(1e-4, 3e-4))
    drawn = replace(
        sure, id="drawn", end_sigma_m=(1e-4, PART_TOLERANCE_M), end_source=(EndSource.EDGE, EndSource.DRAWN)
    )
    assert end_doubt(sure, sc) is None and doubt(sure, sc) is None
    ends = end_doubt(drawn, sc)
    assert ends is not None and ends.code is WeldReason.END_UNCERTAIN and "end tolerance 1 mm" in ends.detail
    assert doubt(drawn, sc) == ends
    _, summary = evaluate((sure, drawn), {})
    det = Detection(sc, "ours", WeldMap((), (), "mm", "inline"), (sure, drawn), {}, {}, summary)
    welds = {w.id: w for w in seam_welds(det, None, None, 0.0, "", sc, True)}
    assert welds["drawn"].code is WeldReason.END_UNCERTAIN and not welds["drawn"].welded
    assert welds["sure"].code is not WeldReason.END_UNCERTAIN


def test_a_closeup_that_finds_where_a_drawn_end_really_is_does_not_escalate() -> None:
    from cell.rescan.escalation import end_shift_m

    a, b = np.zeros(3), np.array([0.1, 0.0, 0.0])
    seen = SeamEstimate(
        "s",
        SeamStatus.FOUND,
        "",
        a,
        b,
        0.9,
        sigma_m=1e-4,
        end_sigma_m=(1e-4, 1e-4),
        end_source=(EndSource.EDGE, EndSource.EDGE),
    )
    drawn = replace(seen, end_source=(EndSource.EDGE, EndSource.DRAWN), end_sigma_m=(1e-4, PART_TOLERANCE_M))
    close = replace(seen, p_end=b + np.array([-0.004, 0.0002, 0.0]))  # the end 4 mm in, 0.2 mm across
    assert end_shift_m(seen, close) == pytest.approx(math.hypot(0.004, 0.0002))  # the cameras were 4 mm off
    assert end_shift_m(drawn, close) == pytest.approx(0.0002)  # the map's end was: only across counts
