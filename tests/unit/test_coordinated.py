"""The coordinated planner: the positioner's axes that keep a pipe's fillet in PA under the torch, the arm's and
the axes' motion timed together at the travel speed relative to the part, and the eight-axis gate."""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path

import numpy as np
import pytest

from cell.coordinated.axes import CurveInF, knots_in_R, pa_axes, positions
from cell.coordinated.gate import MovingScene, joint_limits, off_limits
from cell.scenario import load
from cell.types.curve_estimate import CurveEstimate
from cell.types.positioner import PositionerAxis, TiltRotatePositioner
from cell.types.seams import SeamStatus

R_PIPE, Z_FILLET = 0.1096, 0.04  # [m] the fillet's radius and height above the faceplate


def _circle_F(n: int = 360, off: tuple[float, float] = (0.0, 0.0)) -> CurveInF:
    a = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    radial = np.column_stack([np.cos(a), np.sin(a), np.zeros(n)])
    p = radial * R_PIPE + np.array([off[0], off[1], Z_FILLET])
    tangent = np.column_stack([-np.sin(a), np.cos(a), np.zeros(n)])
    up = np.broadcast_to([0.0, 0.0, 1.0], (n, 3))
    return CurveInF(p, tangent, radial, up, a * R_PIPE)


def _positioner(rotate_deg: float = 400.0) -> TiltRotatePositioner:
    r = math.radians
    return TiltRotatePositioner(
        np.eye(4), 0.8, -0.05, 0.2,
        PositionerAxis("tilt", r(-135), r(135), r(90), r(180), r(900)),
        PositionerAxis("rotate", -r(rotate_deg), r(rotate_deg), r(120), r(240), r(1200)),
    )  # fmt: skip


def test_one_tilt_puts_every_point_of_a_pipes_fillet_in_pa_under_a_still_torch() -> None:
    pos, curve = _positioner(), _circle_F()
    axes = pa_axes(pos, curve)
    assert axes is not None
    assert np.allclose(np.abs(axes[:, 0]), math.radians(45.0))  # the bisector 45 deg from the pipe's axis
    assert np.all(np.diff(axes[:, 1]) > 0) or np.all(np.diff(axes[:, 1]) < 0)  # the rotate axis turns one way
    assert abs(abs(axes[-1, 1] - axes[0, 1]) - math.radians(359.0)) < 1e-6  # the whole loop, one turn
    slope, rot, within = positions(pos, curve, axes)
    assert within and np.abs(slope).max() < 1e-6 and np.abs(rot - 180.0).max() < 1e-6
    p_R = knots_in_R(pos, curve, axes)[0]
    assert np.linalg.norm(p_R - p_R.mean(axis=0), axis=1).max() < 1e-9  # the weld point stands still
    # Clamped 5 mm off centre: the point under the torch wanders by the offset, still in PA.
    off = _circle_F(off=(0.005, 0.0))
    p_off = knots_in_R(pos, off, pa_axes(pos, off))[0]
    spread = np.linalg.norm(p_off - p_off.mean(axis=0), axis=1).max()
    assert 0.004 < spread < 0.0051


def _ellipse_F(lean_deg: float = 35.0, n: int = 240) -> CurveInF:
    """A 42.4 mm tube leaning ``lean_deg`` towards +x, cut flat on the faceplate's plane: the ellipse of its foot."""
    R, lean = 0.0212, math.radians(lean_deg)
    axis, e1 = np.array([math.sin(lean), 0.0, math.cos(lean)]), np.array([math.cos(lean), 0.0, -math.sin(lean)])
    phi = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    u = np.outer(np.cos(phi), e1) + np.outer(np.sin(phi), [0.0, 1.0, 0.0])
    p = R * u - np.outer(R * u[:, 2] / axis[2], axis) + [0.0, 0.0, Z_FILLET]
    return _loop(p, u, np.broadcast_to([0.0, 0.0, 1.0], (n, 3)))


def _saddle_F(n: int = 240, crown_z: float = Z_FILLET) -> CurveInF:
    """A 60.3 mm branch standing on a 114.3 mm run pipe (its axis along x), the saddle's crowns ``crown_z`` [m] up."""
    Rb, Rr = 0.03015, 0.05715
    phi = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    x, y = Rb * np.cos(phi), Rb * np.sin(phi)
    z = np.sqrt(Rr**2 - y**2)
    p = np.column_stack([x, y, z - Rr + crown_z])
    n_run = np.column_stack([np.zeros(n), y, z]) / Rr
    return _loop(p, np.column_stack([np.cos(phi), np.sin(phi), np.zeros(n)]), n_run)


def _loop(p: np.ndarray, n_a: np.ndarray, n_b: np.ndarray) -> CurveInF:
    t = np.roll(p, -1, axis=0) - np.roll(p, 1, axis=0)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
    return CurveInF(p, t, n_a, n_b, s)


@pytest.mark.parametrize(("make", "spread_deg"), [(_ellipse_F, 35.0), (_saddle_F, 16.0)])
def test_the_tilt_follows_a_seam_whose_bisector_turns_and_keeps_every_knot_in_pa(make, spread_deg: float) -> None:
    pos, curve = _positioner(), make()
    axes = pa_axes(pos, curve)
    assert axes is not None
    spread = math.degrees(float(np.ptp(axes[:, 0])))
    assert spread_deg - 2.0 < spread < spread_deg + 2.0  # the tilt follows the bisector's angle to the axis
    assert np.all(np.diff(axes[:, 1]) > 0) or np.all(np.diff(axes[:, 1]) < 0)  # the rotate axis turns one way
    slope, rot, within = positions(pos, curve, axes)
    assert within and np.abs(slope).max() < 0.5 and np.abs(rot - 180.0).max() < 1.0
    # The tilt held at the knots' median: the ellipse's acute and obtuse sides 17.5 deg of rotation off PA (out of
    # tolerance), the saddle's crown and flanks 9.2 deg (just within it).
    held = np.column_stack([np.full(len(axes), np.median(axes[:, 0])), axes[:, 1]])
    assert np.abs(positions(pos, curve, held)[1] - 180.0).max() > 8.0


def test_a_saddle_is_welded_in_pa_with_the_tilt_and_the_rotate_axis_turning_together() -> None:
    """tube-tee-positioner's saddle (its crowns 227 mm above the faceplate) planned, timed and gated as one."""
    from cell.coordinated.plan import plan_coordinated
    from cell.motion.robot import RobotModel
    from cell.process.torch import WeldProcess
    from cell.station.arm import robot_urdf

    sc = load("tube-tee-positioner")
    model = RobotModel.from_urdf(robot_urdf(sc))
    pos = sc.robot.positioner.positioner(sc.X_WR)  # type: ignore[union-attr]
    curve = _saddle_F(crown_z=0.22715)
    process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
    scene = MovingScene.build(model, pos, [], sc.motion.plan.collision)
    q0 = np.radians(sc.robot.home_deg)
    cw = plan_coordinated(model, pos, _estimate(pos, curve), process, sc.motion.plan, scene, q0,
                          rng=np.random.default_rng(0))  # fmt: skip
    assert cw.in_position and np.abs(cw.slope_deg).max() < 1.0 and np.abs(cw.rotation_deg - 180.0).max() < 1.0
    weld = (cw.times >= cw.pieces[2][1]) & (cw.times <= cw.pieces[2][2])
    tilt = np.degrees(cw.axes[weld, 0])
    assert 14.0 < np.ptp(tilt) < 18.0  # the tilt follows the saddle, crowns to flanks, while the arc burns
    rate = np.abs(np.gradient(cw.axes[weld], cw.times[weld], axis=0)).max(axis=0)
    assert rate[0] <= pos.tilt.v_max and rate[1] <= pos.rotate.v_max
    ideal = float(cw.s[-1]) / cw.speed  # the travel speed relative to the part: the loop and overlap at it
    assert ideal < cw.arc_s < ideal + 2.0


def test_a_rotate_axis_too_short_for_the_loop_is_refused() -> None:
    assert pa_axes(_positioner(rotate_deg=170.0), _circle_F()) is None


def test_the_eight_axes_limits_name_the_positioner_axis_that_leaves_them() -> None:
    sc = load("pipe-stub-positioner")
    from cell.motion.robot import RobotModel
    from cell.station.arm import robot_urdf

    model = RobotModel.from_urdf(robot_urdf(sc))
    pos = sc.robot.positioner.positioner(sc.X_WR)  # type: ignore[union-attr]
    lim = joint_limits(model.limits, pos)
    assert lim.names[-2:] == ("tilt", "rotate") and lim.dof == model.dof + 2
    x = np.zeros((3, lim.dof))
    assert off_limits(lim, x) is None
    x[1, -1] = pos.rotate.q_max + 0.01
    assert "rotate" in (off_limits(lim, x) or "")


def _estimate(pos: TiltRotatePositioner, curve: CurveInF) -> CurveEstimate:
    """The closed curve ``curve`` (in F) located exactly, in R at the positioner's home."""
    X = pos.X_R_F(*pos.home)
    n = len(curve.p_F)
    return CurveEstimate(
        "C", SeamStatus.FOUND, p_RS=curve.p_F @ X[:3, :3].T + X[:3, 3], n_abutting_R=curve.n_a_F @ X[:3, :3].T,
        n_receiving_R=curve.n_b_F @ X[:3, :3].T, closed=True, sigma_m=np.full(n, 1e-4), end_sigma_m=(0.0, 0.0),
    )  # fmt: skip


@pytest.fixture(scope="module")
def planned() -> tuple:
    """A pipe's fillet clamped 3.6 mm off the rotate axis of pipe-stub-positioner's positioner, planned."""
    from cell.coordinated.plan import plan_coordinated
    from cell.motion.robot import RobotModel
    from cell.process.torch import WeldProcess
    from cell.station.arm import robot_urdf

    sc = load("pipe-stub-positioner")
    model = RobotModel.from_urdf(robot_urdf(sc))
    pos = sc.robot.positioner.positioner(sc.X_WR)  # type: ignore[union-attr]
    est = _estimate(pos, _circle_F(off=(0.003, -0.002)))
    process = WeldProcess.from_spec(sc.process, sc.robot.stickout_mm)
    scene = MovingScene.build(model, pos, [], sc.motion.plan.collision)
    q0 = np.radians(sc.robot.home_deg)
    cw = plan_coordinated(model, pos, est, process, sc.motion.plan, scene, q0, rng=np.random.default_rng(0))
    return sc, pos, est, process, cw, q0


def test_the_coordinated_weld_is_timed_at_the_travel_speed_on_the_part_and_gated(planned: tuple) -> None:
    _, pos, _, process, cw, q0 = planned
    assert cw.in_position and 2.0 < cw.tcp_spread_mm < 4.0  # the arm corrects the 3.6 mm off-centre clamping
    loop = 2 * math.pi * R_PIPE + process.closed_overlap
    assert abs(cw.s[-1] - loop) < 0.002
    # The weld's speed along the part is the travel speed; its piece lasts the loop at it, the ramps and the crater.
    assert cw.speed == pytest.approx(process.travel_speed)
    ideal = loop / cw.speed
    assert ideal < cw.arc_s < ideal + 2.0
    weld = (cw.times >= cw.pieces[2][1]) & (cw.times <= cw.pieces[2][2])
    rate = np.abs(np.gradient(cw.axes[weld, 1], cw.times[weld]))
    assert rate.max() == pytest.approx(cw.speed / R_PIPE, rel=0.05)  # the rotate axis carries the travel
    # Start and end at home: the arm where it started, the positioner at its home.
    assert np.allclose(cw.q[0], q0) and np.allclose(cw.q[-1], q0) and np.allclose(cw.axes[-1], pos.home)


def test_the_simulator_turns_the_part_and_the_torch_follows_its_seam(planned: tuple) -> None:
    from cell.pipeline.coordinated.play import play, quality
    from cell.pipeline.detect import read_weldmap
    from cell.pipeline.geometry import open_cell

    sc, pos, est, _, cw, _ = planned
    with open_cell(sc, read_weldmap(sc)) as station:
        ex, back = play(station, cw, record_dt=0.1)
        axes_end = station.positioner.axes  # type: ignore[union-attr]
        # The bead, where the part now lies, carried back into the faceplate's frame at home.
        X_W_F = station.positioner.X_W_true @ sc.X_WR @ pos.X_R_F(*pos.home)  # type: ignore[union-attr]
        ends_W = station.sim.bead_segments().reshape(-1, 3)
    assert np.allclose(axes_end, pos.home)  # the positioner played back home with the arm
    # The bead was laid on the turning part where the wire's tip was: on the fillet all round (laid in the world
    # it would be a short smear where the torch stands, off the fillet once the part turns home).
    p_F = (ends_W - X_W_F[:3, 3]) @ X_W_F[:3, :3]
    d = p_F[:, :2] - np.array([0.003, -0.002])
    assert np.hypot(np.linalg.norm(d, axis=1) - R_PIPE, p_F[:, 2] - Z_FILLET).max() < 0.01e-3  # measured 0.001 mm
    turn = np.sort(np.arctan2(d[:, 1], d[:, 0]))
    assert np.diff(np.r_[turn, turn[0] + 2 * math.pi]).max() < math.radians(3.0)  # the whole loop, no gap
    q = quality(ex, back, np.asarray(est.p_RS), closed=True)
    assert q.tcp_max_mm < 0.05 and q.short_start_mm == 0.0  # the whole loop, on the seam the part carries
    assert q.speed_mm_s == pytest.approx(cw.speed * 1000.0, rel=0.01)  # relative to the turning part
    moved = np.linalg.norm(ex.tcp_W[ex.arc_on] - ex.tcp_W[ex.arc_on].mean(axis=0), axis=1).max()
    assert moved < 0.005  # the torch nearly still in the world while the part turns under it


def test_the_krl_program_moves_e2_e3_in_the_turning_base_and_passes_the_check(planned: tuple, tmp_path: Path) -> None:
    from cell.export.checks.calls import check_all
    from cell.export.checks.program import read_programs
    from cell.export.coordinated_program import write_coordinated_programs
    from cell.motion.robot import RobotModel
    from cell.station.arm import robot_urdf

    sc, pos, _, _, cw, _ = planned
    robot = RobotModel.from_urdf(robot_urdf(sc))
    write_coordinated_programs("krl", [cw], robot, pos, "pipe", tmp_path)
    programs, found = read_programs(tmp_path)
    assert not found and not check_all(programs, robot)  # S, T on the arm at every point's own E2 / E3
    dat_path = next(tmp_path.glob("*.dat"))
    dat = dat_path.read_text()
    e3 = [float(v) for v in re.findall(r"E6POS XP\d+=\{[^}]*E3 ([-\d.]+)", dat)]
    assert len(set(e3)) > 10 and max(e3) - min(e3) > 360.0  # the rotate axis turns the loop, point by point
    src = next(tmp_path.glob("*.src"))
    # The fillet is a circle in the part: five CIRC of about 73 deg (the loop and its overlap) in the turning base,
    # their points on the planned circle; an auxiliary point moved 0.2 mm off it is found by the check.
    circs = re.findall(r"^CIRC (XP\d+), XP\d+, CA ([\d.]+)$", src.read_text(), re.M)
    assert len(circs) == 5 and sum(float(ca) for _, ca in circs) == pytest.approx(365.2, abs=0.2)
    aux = re.search(rf"(DECL E6POS {circs[1][0]}=\{{X )([-\d.]+)", dat)
    assert aux is not None
    dat_path.write_text(dat.replace(aux.group(0), f"{aux.group(1)}{float(aux.group(2)) + 0.2:.4f}"))
    assert any(f.code == "circ" for f in check_all(read_programs(tmp_path)[0], robot))
    dat_path.write_text(dat)
    text = src.read_text().replace("Positioner chain", "Positioner")  # the chain not stated: the base stands still
    src.write_text(text)
    programs, _ = read_programs(tmp_path)
    assert any(f.code in ("kinematics", "status_turn") for f in check_all(programs, robot))


def test_a_seam_that_is_no_circle_in_the_part_is_written_in_chords(planned: tuple) -> None:
    from dataclasses import replace

    from cell.export.coordinated_program import CHORD_TOL_M, coordinated_moves, program_path_off

    cw = planned[4]
    circles = coordinated_moves(cw)
    assert {mv.kind for mv in circles} == {"CIRC"} and program_path_off(cw, circles) < 1e-6  # a true circle
    X = np.array(cw.X_FT)
    X[:, 0, 3] *= 1.02  # an ellipse 2 % out of round: no circle within the tolerance
    moves = coordinated_moves(replace(cw, X_FT=X))
    assert {mv.kind for mv in moves} == {"LIN"} and program_path_off(replace(cw, X_FT=X), moves) <= CHORD_TOL_M
    assert moves[0].start == 0 and moves[-1].end == len(X) - 1
    assert max(mv.axes_dev for mv in moves) < math.radians(0.01)  # the axes turn in step with the chords


def test_a_circle_whose_axes_swing_is_split_finer_into_circular_moves_not_chords(planned: tuple) -> None:
    """tube-tee-positioner's end-plate arcs (210-222 deg, the tilt turning 70 deg): twelve moves, four per 90 deg,
    left the planned E2/E3 0.63-0.75 deg off the controller's interpolation, so they were written in chords; split
    into moves down to 10 deg they are circles, each within 0.5 deg. Here the loop's tilt swings 5 deg four times
    round, which twenty moves cannot follow within 0.5 deg."""
    from dataclasses import replace

    from cell.export.coordinated_program import MAX_AXES_DEV_RAD, MIN_CIRC_SWEEP_RAD, coordinated_moves

    cw = planned[4]
    s = np.asarray(cw.s) / float(cw.s[-1])
    axes = np.array(cw.knot_axes, dtype=float)
    axes[:, 0] += math.radians(5.0) * np.sin(2.0 * math.pi * 4.0 * s)  # the tilt swinging 5 deg, four times
    swung = replace(cw, knot_axes=axes)
    moves = coordinated_moves(swung)
    assert {mv.kind for mv in moves} == {"CIRC"}, [mv.kind for mv in moves]
    assert len(moves) > 4 * math.ceil(sum(mv.angle for mv in moves) / math.radians(90.0))  # beyond the old bound
    assert max(mv.axes_dev for mv in moves) <= MAX_AXES_DEV_RAD
    assert min(mv.angle for mv in moves) >= 0.9 * MIN_CIRC_SWEEP_RAD
    assert all(mv.start < mv.aux < mv.end for mv in moves)
    assert moves[0].start == 0 and moves[-1].end == len(s) - 1
    assert all(a.end == b.start for a, b in itertools.pairwise(moves))


@pytest.fixture(scope="module")
def woven(planned: tuple) -> tuple:
    """The same fillet welded with a zigzag weave (3 mm at 0.5 Hz, 8 mm/s)."""
    from cell.coordinated.gate import MovingScene
    from cell.coordinated.plan import plan_coordinated
    from cell.motion.robot import RobotModel
    from cell.station.arm import robot_urdf
    from cell.types.procedure import Weave, WeldProcedure

    sc, pos, est, process, _, q0 = planned
    model = RobotModel.from_urdf(robot_urdf(sc))
    proc = WeldProcedure(name="PA-weave", travel_speed_mm_s=8.0, weave=Weave("zigzag", 3.0, 0.5, (0.2, 0.2)))
    scene = MovingScene.build(model, pos, [], sc.motion.plan.collision)
    cw = plan_coordinated(model, pos, est, process, sc.motion.plan, scene, q0, rng=np.random.default_rng(0),
                          procedure=proc)  # fmt: skip
    return sc, pos, est, cw, model


def test_a_weave_is_laid_across_the_fillet_in_the_parts_frame_and_measured_without_it(woven: tuple) -> None:
    from cell.export.coordinated_program import coordinated_moves, program_path_off
    from cell.pipeline.coordinated.play import quality, weave_at_records
    from cell.types.execution import Execution

    _, pos, est, cw, model = woven
    assert cw.weave_F is not None
    w = np.asarray(cw.weave_F)
    # Across the fillet in its local cross-section in F: square to the circle's tangent, in the faceplate's
    # plane's radial-up cross-section, 1.5 mm either side at most.
    p = np.asarray(cw.line_FT)[:, :3, 3]
    tangent = np.gradient(p, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    assert np.abs(np.sum(w * tangent, axis=1)).max() < 1e-5
    assert 1.45e-3 < np.linalg.norm(w, axis=1).max() <= 1.5e-3 + 1e-9
    # The pass's line is the circle (the controller's weave on ArcC); the woven torch only chords.
    line_moves = coordinated_moves(cw, woven=False)
    assert {mv.kind for mv in line_moves} == {"CIRC"} and program_path_off(cw, line_moves, woven=False) < 1e-6
    # The planned torch every 0.1 s, carried back into the part's frame at home by the positioner's motion (the
    # simulator's playback of the same is measured by the benchmark: benchmarks/bench_coordinated.py --weave).
    k = np.unique(np.r_[np.searchsorted(cw.times, np.arange(0.0, cw.times[-1], 0.1)), len(cw.times) - 1])
    tip_R = np.array([model.fk(q)[:3, 3] for q in cw.q[k]])
    back = np.array([np.linalg.solve(pos.move(*a), np.r_[p, 1.0])[:3] for a, p in zip(cw.axes[k], tip_R, strict=True)])
    ex = Execution(cw.times[k], cw.q[k], tip_R, np.asarray(cw.arc_on, bool)[k], ())
    raw = quality(ex, back, np.asarray(est.p_RS), closed=True)
    weave = weave_at_records(cw, ex, pos.X_R_F(*pos.home)[:3, :3])
    q = quality(ex, back, np.asarray(est.p_RS), closed=True, weave_R=weave)
    assert raw.tcp_max_mm > 1.4  # the torch weaves 1.5 mm either side of the fillet
    assert q.tcp_max_mm < 0.05 and q.short_start_mm == 0.0  # taken off: on the fillet all round (0.021 mm)


def test_the_weaving_programs_weave_as_the_fixed_arms_do(woven: tuple, tmp_path: Path) -> None:
    from cell.export.checks.calls import check_all
    from cell.export.checks.program import read_programs
    from cell.export.coordinated_program import write_coordinated_programs

    _, pos, _, cw, model = woven
    write_coordinated_programs("rapid", [cw], model, pos, "pipe", tmp_path)
    mod = next(tmp_path.glob("*.mod")).read_text()
    # RAPID: the circle's ArcC along the pass's line, the weave the controller's (ABB's zigzag, 3 mm wide).
    assert len(re.findall(r"ArcCE?n?d? p\d+, p\d+, vWeld, sm1, wd1 \\Weave:=wv1,", mod)) == 5
    assert re.search(r"weavedata wv1 := \[1,0,16(\.0+)?,3(\.0+)?,", mod) is not None
    # KRL (plain I/O, no weave package): the woven path itself in chords in the turning base, checked as ever.
    write_coordinated_programs("krl", [cw], model, pos, "pipe", tmp_path)
    src = next(tmp_path.glob("*.src")).read_text()
    assert "\nCIRC " not in src and src.count("\nLIN ") > 200 and "weave zigzag 3 mm at 0.5 Hz" in src
    assert not check_all(read_programs(tmp_path)[0], model)
