"""The triangle and circle weaves: their geometry (amplitude, frequency, dwells, shape, on the pass line at both
ends), their validation in a scenario, and each planned on the tiny cell's vertical seam (IK, timing, the safety
gate) with the TCP on the seam plus the intended weave."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, URDF

from cell import scenario as sc
from cell.errors import ScenarioError
from cell.gate import find_violations
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds
from cell.process.procedures import select_procedures
from cell.process.torch import WeldProcess
from cell.process.weave import cross_section, intended_offsets, knot_spacing, weave_offsets
from cell.types.plan import SeamTask
from cell.types.procedure import Weave, WeldProcedure

V, LENGTH = 0.004, 0.0615  # [m/s], [m]: 15.375 wavelengths of 4 mm at 1 Hz
S = np.linspace(0.0, LENGTH, 61501)  # every 1 um
HALF = 0.002  # [m] a 4 mm weave
FENCE1 = (sc.SCENARIO_DIR / "fence1.yaml").read_text()


def _time_at(mask: np.ndarray) -> float:
    """Time [s] per wavelength the samples in ``mask`` stand for (over the whole woven part)."""
    return float(np.mean(mask))


def test_triangle_straight_legs_sharp_turns_dwells_and_ends_on_the_line() -> None:
    weave = Weave("triangle", 4.0, 1.0, (0.15, 0.25))
    lat, lift = weave_offsets(S, LENGTH, weave, V)
    assert not lift.any()
    assert lat[0] == 0.0 and lat[1] > 0.0  # from the line straight out towards face A, at full width at once
    assert lat.max() == pytest.approx(HALF, abs=1e-12) and lat.min() == pytest.approx(-HALF, abs=1e-12)
    # the last crossing of the line: 15 whole wavelengths (60 mm) plus the 0.15 s dwell and one 0.3 s crossing
    # (r = (1 - 0.4) / 2) out and back: 61.8 mm is past the weld end, so the weave ends at 60 mm on the line
    woven = S <= 0.060 + 1e-9
    assert not lat[~woven].any() and np.abs(lat[woven][-50:]).max() > 0.0
    one = (S >= 0.020) & (S < 0.024)  # one wavelength
    assert _time_at(np.isclose(lat[one], HALF, atol=1e-12)) == pytest.approx(0.15, abs=0.002)
    assert _time_at(np.isclose(lat[one], -HALF, atol=1e-12)) == pytest.approx(0.25, abs=0.002)
    # straight legs at 4 mm per 0.3 s across the seam: the slope is one of 0, +-13.33 mm/s over the travel speed
    slope = np.diff(lat) / np.diff(S) * V
    legs = np.abs(slope) > 1e-9
    assert np.abs(slope[legs]) == pytest.approx(np.full(legs.sum(), 0.004 / 0.3), rel=1e-6)
    turns = np.count_nonzero(np.diff(np.sign(np.round(slope[S[1:] < 0.060], 9))) != 0)
    assert turns == 4 * 15  # four sharp turns a wavelength (into and out of each dwell)
    off_line = lat[(S > 0.0005) & (lat != 0.0)]
    crossings = np.count_nonzero(np.diff(np.sign(off_line)) != 0)
    assert crossings == 2 * 15 - 1  # the line crossed twice a wavelength (one period of 1 / f)


def test_circle_in_the_cross_section_through_the_pass_line() -> None:
    weave = Weave("circle", 4.0, 1.0)
    lat, lift = weave_offsets(S, LENGTH, weave, V)
    woven = S <= 0.060 + 1e-9  # whole turns only: 15, then on the line
    assert not lat[~woven].any() and not lift[~woven].any()
    r = np.hypot(lat[woven], lift[woven] - HALF)  # about the centre width / 2 out of the root
    assert r == pytest.approx(np.full(woven.sum(), HALF), abs=1e-12)  # a circle of the width's diameter
    assert lift.min() == pytest.approx(0.0, abs=1e-12) and lift.max() == pytest.approx(2 * HALF, abs=1e-9)
    assert lat.max() == pytest.approx(HALF, abs=1e-9) and lat.min() == pytest.approx(-HALF, abs=1e-9)
    phi = np.unwrap(np.arctan2(lat[woven], HALF - lift[woven]))
    assert phi[-1] == pytest.approx(15 * 2 * np.pi, abs=1e-6)  # one turn a period: 15 in 60 mm at 4 mm/s
    rate = np.diff(phi) / np.diff(S[woven]) * V  # [rad/s]
    s_mid = S[woven][1:]
    middle = (s_mid > 0.004) & (s_mid < 0.056)  # turns 2 to 14
    assert rate[middle] == pytest.approx(np.full(middle.sum(), 2 * np.pi), rel=1e-6)  # constant angular speed
    assert rate[0] < 1e-3 and rate[-1] < 1e-3  # the first turn eased in from rest, the last out to rest
    assert rate.min() > -1e-9 and rate.max() == pytest.approx(1.512 * 2 * np.pi, rel=1e-3)  # always onwards
    assert lat[np.argmin(np.abs(S - 0.009))] == pytest.approx(HALF, abs=1e-9)  # a quarter turn on: face A side


def test_the_intended_path_is_read_back_for_every_pattern() -> None:
    d, n_a, n_b = np.array([0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    e, b = cross_section(d, n_a, n_b)
    p = np.outer(S[::500], d)
    for pattern in ("zigzag", "triangle", "circle"):
        proc = WeldProcedure("w", travel_speed_mm_s=4.0, weave=Weave(pattern, 4.0, 1.0))
        lat, lift = weave_offsets(S[::500], LENGTH, proc.weave, V)
        tcp = p + np.outer(lat, e) + np.outer(lift, b)
        back = tcp - intended_offsets(tcp, np.zeros(3), d, LENGTH, proc, 0, e, b)
        assert back == pytest.approx(p, abs=1e-12), pattern
    sharp = WeldProcedure("t", travel_speed_mm_s=4.0, weave=Weave("triangle", 4.0, 1.0))
    assert knot_spacing(sharp, 0, 0.002) == pytest.approx(0.004 / 20)  # the sharp turns: coarser knots
    assert knot_spacing(replace(sharp, weave=Weave("circle", 4.0, 1.0)), 0, 0.002) == pytest.approx(0.004 / 24)


@pytest.mark.parametrize(
    ("weave", "needle"),
    [
        ("{pattern: circle, width_mm: 4, frequency_hz: 1, dwell_s: [0.1, 0.1]}", "a circle weave takes no dwells"),
        ("{pattern: spiral, width_mm: 4, frequency_hz: 1}", "'none', 'zigzag', 'triangle' or 'circle'"),
        ("{pattern: triangle, width_mm: 4, frequency_hz: 2, dwell_s: [0.3, 0.2]}", "leave no time to cross"),
    ],
)
def test_weave_patterns_validated(weave: str, needle: str) -> None:
    with pytest.raises(ScenarioError) as err:
        sc.from_yaml(FENCE1 + f"procedures:\n  - {{name: a, weave: {weave}}}\n", sc.SCENARIO_DIR)
    assert needle in err.value.message
    ok = sc.from_yaml(FENCE1 + "procedures:\n  - {name: a, weave: {pattern: circle, width_mm: 4, frequency_hz: 1}}\n")
    assert ok.weld_procedures()[0].weave == Weave("circle", 4.0, 1.0, (0.0, 0.0))


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.mark.parametrize(
    ("weave", "lat_tol", "dev_max"),
    [(Weave("triangle", 4.0, 1.0, (0.15, 0.15)), 0.025, 0.12), (Weave("circle", 4.0, 1.0), 0.005, 0.004)],
)
def test_planned_gated_and_on_the_intended_weave(
    robot: RobotModel, weave: Weave, lat_tol: float, dev_max: float
) -> None:
    side = SeamTask(*SIDE_SEAM)
    down = SeamTask("side", side.p_end, side.p_start, side.n_a, side.n_b)
    proc = WeldProcedure("w", position="PF", travel_speed_mm_s=4.0, travel_angle_deg=-20.0, weave=weave)
    sel = select_procedures([down], {"side": "T"}, {"side": 4.0}, [proc])
    process = WeldProcess.from_spec(sc.ProcessSpec())
    plan = plan_welds(robot, [down], HOME, process, OBSTACLES, procedures=sel)
    assert plan.outcome("side").feasible, plan.outcome("side").reason
    assert find_violations(robot, plan, HOME, checker=CollisionChecker(robot, OBSTACLES)) == []
    weld = next(s for s in plan.segments if s.arc_on)
    a, d = side.p_start, (side.p_end - side.p_start) / side.length  # welded upwards
    e, b = cross_section(d, side.n_a, side.n_b)
    p = np.array([robot.fk(q)[:3, 3] for q in weld.trajectory.q])
    lat, lift = (p - a) @ e * 1000.0, (p - a) @ b * 1000.0  # [mm]
    assert lat.max() == pytest.approx(2.0, abs=lat_tol) and lat.min() == pytest.approx(-2.0, abs=lat_tol)
    assert lift.max() == pytest.approx(4.0 if weave.pattern == "circle" else 0.0, abs=0.01)
    off = intended_offsets(p, a, d, side.length, proc, 0, e, b)
    on_seam = p - off - (a + np.outer((p - a) @ d, d))
    dev = np.linalg.norm(on_seam, axis=1) * 1000.0  # the triangle: its sharp turns rounded over about a knot
    assert dev.max() < dev_max and float(np.sqrt(np.mean(dev**2))) < 0.03
    assert np.linalg.norm(p[-1] - side.p_end) < 5e-6  # the weld ends on the seam (the program's LIN point)
