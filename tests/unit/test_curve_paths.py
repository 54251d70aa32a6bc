"""Torch paths along curves: the torch on the local bisector with the travel angle along the local tangent, a full
circle with its overlap, knots close enough on a tight curve, the wrist's whole turns, the weld measured against a
curve, and the circle through a circular move's points."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cell.export.circles import circle_through, fit_circle
from cell.planning.curves import curve_path, curve_poses
from cell.planning.curves.search import _turns, knot_spacing
from cell.process.curve_quality import curve_weld_quality
from cell.process.torch import WeldProcess, measured_angles
from cell.types import SeamStatus
from cell.types.curve_estimate import CurveEstimate
from cell.types.robot import JointLimits

PROCESS = WeldProcess(0.008, math.radians(45), 0.0, math.radians(10), 0.0, 0.015, 0.015, math.pi, 0.05, 0.05, 0.25)


def _tube_on_plate(r: float = 0.03, lean_deg: float = 0.0, n: int = 180) -> CurveEstimate:
    """The foot of a tube standing on a plate z = 0 (leaning about x: an ellipse), counter-clockwise from +x."""
    lean = math.radians(lean_deg)
    axis = np.array([0.0, math.sin(lean), math.cos(lean)])
    t = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    p = np.column_stack([r * np.cos(t), r * np.sin(t) / math.cos(lean), np.zeros(n)]) + np.array([0.0, 0.9, 0.0])
    d = p - [0.0, 0.9, 0.0]
    radial = d - np.outer(d @ axis, axis)
    n_tube = radial / np.linalg.norm(radial, axis=1, keepdims=True)
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    return CurveEstimate("TUBE>PLATE", SeamStatus.FOUND, p_RS=p, n_abutting_R=n_tube, n_receiving_R=up,
                         closed=True, sigma_m=np.full(n, 1e-4), end_sigma_m=(0.0, 0.0))  # fmt: skip


@pytest.mark.parametrize("lean_deg", [0.0, 20.0])
@pytest.mark.parametrize("reverse", [False, True])
def test_the_torch_keeps_its_angles_to_the_local_faces_all_round(lean_deg: float, reverse: bool) -> None:
    est = _tube_on_plate(lean_deg=lean_deg)
    path = curve_path(est, 0.002, start=0.05, reverse=reverse, overlap=0.01)
    X = curve_poses(path, PROCESS, spin=0.7)
    for i in range(0, len(X), 7):
        work, travel = measured_angles(X[i], path.t_R[i], path.n_a_R[i], path.n_b_R[i])
        assert work == pytest.approx(math.radians(45.0), abs=1e-9)  # on the local bisector
        assert travel == pytest.approx(math.radians(10.0), abs=1e-9)  # pushing along the local tangent
        assert np.linalg.norm(X[i][:3, 3] + PROCESS.standoff * X[i][:3, 2] - path.p_R[i]) < 1e-12
    z = X[:, :3, 2]
    step = np.degrees(np.arccos(np.clip(np.sum(z[1:] * z[:-1], axis=1), -1, 1)))
    turn = np.degrees(np.arccos(np.clip(np.sum(path.t_R[1:] * path.t_R[:-1], axis=1), -1, 1)))
    assert np.max(step) < 1.01 * np.max(turn) + 1e-9  # continuous: it turns no faster than the curve
    way = float(np.sum(np.cross(path.t_R[:-1], path.t_R[1:])[:, 2]))
    assert math.copysign(1.0, way) == (-1.0 if reverse else 1.0)  # the way round asked for


def test_a_full_circle_is_welded_on_past_its_start_by_the_overlap() -> None:
    est = _tube_on_plate(r=0.03)
    path = curve_path(est, 0.002, start=0.02, overlap=0.01)
    loop = 2.0 * math.pi * 0.03
    assert path.length == pytest.approx(loop + 0.01, abs=2e-4)
    assert path.overlap == pytest.approx(0.01, abs=2e-4)
    k = int(np.argmin(np.abs(path.s - loop)))  # one loop round: back at the start
    assert np.linalg.norm(path.p_R[k] - path.p_R[0]) < 1e-3
    assert np.linalg.norm(path.p_R[-1] - path.p_R[0]) == pytest.approx(0.01, abs=3e-4)  # 10 mm over the start
    assert np.max(np.diff(path.s)) <= 0.002 + 1e-12


def test_knots_are_closer_on_a_tight_curve() -> None:
    tight, wide = knot_spacing(_tube_on_plate(r=0.024), 0.0025), knot_spacing(_tube_on_plate(r=0.5, n=720), 0.0025)
    assert tight == pytest.approx(0.024 * math.radians(2.0), rel=0.05)  # 2 deg of turn between knots
    assert wide == 0.0025


def test_the_wrist_is_centred_by_whole_turns_only() -> None:
    lim = JointLimits(("a1", "a2", "a3", "a4", "a5", "a6"), np.radians([-155, -180, -15, -350, -130, -350]),
                      np.radians([155, 65, 158, 350, 130, 350]), np.ones(6), np.ones(6), np.ones(6))  # fmt: skip
    Q = np.zeros((5, 6))
    Q[:, 3] = np.radians(np.linspace(200.0, 340.0, 5))  # A4 and A6 off to one side
    Q[:, 5] = np.radians(np.linspace(100.0, 300.0, 5))
    shift = _turns(Q, 0.0, lim)
    assert np.allclose(shift[:3], 0.0) and shift[4] == 0.0
    assert np.allclose(np.degrees(shift[[3, 5]]), [-360.0, -360.0])


def test_a_weld_along_a_circle_is_measured_across_it() -> None:
    t = np.linspace(0.0, 2.0 * math.pi, 2000, endpoint=False)
    truth = np.column_stack([0.05 * np.cos(t), 0.05 * np.sin(t), np.zeros_like(t)])
    u = np.linspace(0.0, 2.0 * math.pi * 0.8, 500)  # 80 % of the loop, 0.3 mm outside it
    tcp = np.column_stack([0.0503 * np.cos(u), 0.0503 * np.sin(u), np.zeros_like(u)])
    q = curve_weld_quality(np.linspace(0.0, 10.0, 500), tcp, truth, closed=True)
    assert q.tcp_max_mm == pytest.approx(0.3, abs=0.01)
    assert q.tcp_rms_mm == pytest.approx(0.3, abs=0.01)
    assert q.short_start_mm == pytest.approx(0.2 * 2.0 * math.pi * 50.0, abs=2.0)  # the loop's 20 % unwelded


def test_a_curve_welded_in_two_arcs_is_measured_over_its_arcs_not_the_air_between() -> None:
    """The far arc welded first, then the near one after 5 s in the air: travel speed 8 mm/s and the 450 mm the
    two arcs weld, not the jump between them (before: 23.9 mm/s, 570 mm)."""

    def arc(a0: float, a1: float, t0: float) -> tuple[np.ndarray, np.ndarray]:
        t = t0 + np.arange(int(0.1 * (a1 - a0) / 0.008 * 1000.0)) / 1000.0
        a = a0 + (t - t0) * 0.008 / 0.1
        return t, np.column_stack([0.1 * np.cos(a), 0.1 * np.sin(a), np.zeros_like(a)])

    u = np.linspace(0.0, 2.0 * math.pi, 4001)
    truth = np.column_stack([0.1 * np.cos(u), 0.1 * np.sin(u), np.zeros_like(u)])
    t_far, p_far = arc(2.5, 5.0, 0.0)
    t_near, p_near = arc(0.0, 2.0, t_far[-1] + 5.0)
    q = curve_weld_quality(np.r_[t_far, t_near], np.r_[p_far, p_near], truth, closed=True)
    assert q.speed_mm_s == pytest.approx(8.0, abs=0.01)
    assert q.length_mm == pytest.approx(450.0, abs=0.5)


def test_the_circle_through_three_points() -> None:
    a, b, c = np.array([50.0, 0.0, 0.0]), np.array([0.0, 50.0, 0.0]), np.array([-50.0, 0.0, 0.0])
    got = circle_through(a, b, c)
    assert got is not None
    centre, r, angle = got
    assert np.allclose(centre, 0.0, atol=1e-9) and r == pytest.approx(50.0)
    assert math.degrees(angle) == pytest.approx(180.0)
    assert circle_through(a, (a + c) / 2.0, c) is None  # on one line: no circle
    centre, normal, r, err = fit_circle(np.vstack([a, b, c, [0.0, -50.0, 0.0]]))
    assert r == pytest.approx(50.0) and err < 1e-9 and abs(normal[2]) == pytest.approx(1.0)


def test_a_weave_follows_the_curve_round_across_the_local_bisector() -> None:
    from cell.planning.curves.weave import cross_sections, woven
    from cell.process.weave import weave_offsets
    from cell.types.procedure import Weave, WeldProcedure

    proc = WeldProcedure("weave", weave=Weave("zigzag", 3.0, 1.0))
    path = curve_path(_tube_on_plate(r=0.05), 0.0005, overlap=0.01)
    X = curve_poses(path, PROCESS)
    off = woven(X, path, proc)[:, :3, 3] - X[:, :3, 3]
    lat, _ = weave_offsets(path.s, path.length, proc.weave, 0.008)
    e, b = cross_sections(path)
    assert np.max(np.abs(np.sum(off * path.t_R, axis=1))) < 1e-12  # never along the curve
    assert np.allclose(off, lat[:, None] * e, atol=1e-12)  # across the local bisector, as on a straight seam
    assert np.max(np.abs(np.sum(e * b, axis=1))) < 1e-12
    assert np.max(np.linalg.norm(off, axis=1)) == pytest.approx(1.5e-3, rel=0.02)  # half the width either side
    horizontal = e[:, 2]  # a tube square on a plate: across the 45 deg bisector, half up and half in
    assert np.allclose(np.abs(horizontal), math.sqrt(0.5), atol=1e-9)


def test_close_ups_look_at_the_doubtful_stretch_of_a_curve_in_nearly_straight_pieces() -> None:
    from dataclasses import replace

    from cell.rescan.curve_views import MAX_SAGITTA_M, curve_view_targets

    est = _tube_on_plate(r=0.05, n=360)
    doubtful = est.p_RS[:, 1] > 0.9  # the far half's sigma over the tolerance
    est = replace(est, sigma_m=np.where(doubtful, 5e-4, 1e-4))
    targets = curve_view_targets(est, 3e-4)
    assert 3 <= len(targets) <= 6  # 157 mm in pieces of about 40 mm (a 4 mm sagitta on a 50 mm radius)
    for t in targets:
        assert t.p_start[1] > 0.9 - 1e-9 and t.p_end[1] > 0.9 - 1e-9
        mid = 0.5 * (t.p_start + t.p_end)
        assert 0.05 - np.linalg.norm(mid[:2] - [0.0, 0.9]) <= MAX_SAGITTA_M + 1e-9  # the chord near the curve
        assert abs(float(t.bisector @ [0.0, 0.0, 1.0]) - math.sqrt(0.5)) < 0.05  # looking into the fillet
    assert curve_view_targets(est, 1e-3) == []  # nowhere doubtful: no close-up
