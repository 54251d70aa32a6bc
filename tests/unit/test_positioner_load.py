"""A welding engineer's checks on a positioner: the part's mass and its weight's moments against the positioner's
ratings, and a positioner move swept against the arm standing where it is."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cell.config.motion import CollisionOptions
from cell.errors import PositionerFault, PositionerLoadError
from cell.geometry import make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.pipeline.positioned.sweep import clear_route, move_hit, swept_bodies
from cell.positioner.bodies import positioner_parts
from cell.positioner.payload import G_M_S2, check_load, part_load
from cell.scenario.positioner_specs import PositionerSpec
from cell.types import Box, Part
from cell.types.positioner import TiltRotatePositioner

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"


def _positioner(X_WP_xyz: tuple[float, float, float] = (0.0, 0.0, 0.0), **keys: float) -> TiltRotatePositioner:
    spec = PositionerSpec(base_xyz_m=X_WP_xyz, tilt_height_mm=900.0, faceplate_offset_mm=-100.0, **keys)
    return spec.positioner(np.eye(4))


def _bar(centre_F: tuple[float, float, float], size: tuple[float, float, float]) -> Part:
    return Part("BAR", Box(make_pose(p=centre_F), np.array(size)))


def test_mass_and_moments_of_a_bar_clamped_off_centre() -> None:
    pos = _positioner()
    # 1.0 x 0.1 x 0.1 m of steel, its centre 0.2 m out along F's y and 0.05 m above the faceplate (0.1 m below
    # the tilt axis): 78.5 kg, 0.2 m from the rotate axis, hypot(0.2, 0.05) m from the tilt axis at worst.
    load = part_load([_bar((0.0, 0.2, 0.05), (1.0, 0.1, 0.1))], pos)
    assert load.mass_kg == pytest.approx(78.5)
    assert np.allclose(load.p_F, [0.0, 0.2, 0.05])
    w = 78.5 * G_M_S2
    assert load.tilt_torque_nm == pytest.approx(w * math.hypot(0.2, 0.05 - 0.1))
    assert load.rotate_torque_nm == pytest.approx(w * 0.2)  # the tilt reaches 90 deg: the lever whole
    check_load(load, pos)  # a 400 kg class unit holds it


@pytest.mark.parametrize(
    "keys, code",
    [
        ({"payload_kg": 50.0}, PositionerFault.PAYLOAD),
        ({"tilt_torque_nm": 100.0}, PositionerFault.TILT_TORQUE),
        ({"rotate_torque_nm": 100.0}, PositionerFault.ROTATE_TORQUE),
    ],
)
def test_a_load_over_a_rating_is_refused_naming_it(keys: dict[str, float], code: PositionerFault) -> None:
    pos = _positioner(**keys)
    load = part_load([_bar((0.0, 0.2, 0.05), (1.0, 0.1, 0.1))], pos)
    with pytest.raises(PositionerLoadError) as info:
        check_load(load, pos)
    e = info.value
    assert e.code is code and e.exit_code == 10 and e.needed == next(iter(keys.values()))
    assert e.value > e.needed and f"robot.positioner.{next(iter(keys))}" in e.message


def test_the_same_part_clamped_nearer_the_tilt_axis_weighs_less_on_it() -> None:
    pos = _positioner()
    far = part_load([_bar((0.0, 0.4, 0.05), (0.2, 0.1, 0.1))], pos)
    near = part_load([_bar((0.0, 0.0, 0.1), (0.2, 0.1, 0.1))], pos)  # its centre on the tilt axis
    assert near.mass_kg == pytest.approx(far.mass_kg)
    assert near.tilt_torque_nm == pytest.approx(0.0, abs=1e-9)
    assert far.tilt_torque_nm == pytest.approx(15.7 * G_M_S2 * math.hypot(0.4, -0.05))


@pytest.fixture(scope="module")
def arm() -> RobotModel:
    return RobotModel.from_urdf(URDF)


Q_ARM = np.radians([0.0, -90.0, 90.0, 0.0, 45.0, 0.0])


def _bar_beside(arm: RobotModel) -> tuple[TiltRotatePositioner, tuple[Part, ...]]:
    """A positioner whose 1.1 m bar, clamped along F's y, passes the arm's torch (at ``Q_ARM``) 0.6 m out when
    tilted 45 deg."""
    pos0 = PositionerSpec(
        base_xyz_m=(0.0, 0.0, 0.0), tilt_height_mm=900.0, faceplate_offset_mm=0.0, faceplate_diameter_mm=150.0
    )
    p_on = pos0.positioner(np.eye(4)).X_R_F(math.radians(45.0), 0.0) @ np.array([0.0, 0.6, 0.02, 1.0])
    base = tuple(float(v) for v in arm.fk(Q_ARM)[:3, 3] - p_on[:3])
    pos = pos0.model_copy(update={"base_xyz_m": base}).positioner(np.eye(4))
    return pos, (Part("BAR", Box(pos.X_R_F(0.0, 0.0) @ make_pose(p=(0.0, 0.55, 0.02)), np.array([0.05, 1.1, 0.04]))),)


def test_a_move_that_sweeps_the_part_through_the_arm_is_found(arm: RobotModel) -> None:
    """A 1 m bar on the faceplate tilted a quarter turn sweeps a quarter circle; the arm's torch stands on that
    circle at 45 deg: clear of the bar at both ends of the move, hit on the way."""
    q = Q_ARM
    pos, home = _bar_beside(arm)
    opt = CollisionOptions()
    for t in (0.0, math.pi / 2):  # the ends are clear
        at = [p.transformed(pos.move(t, 0.0)) for p in home] + list(positioner_parts(pos, t, 0.0))
        assert CollisionChecker(arm, at, opt).check(q) is None
    hit = move_hit(arm, q, home, pos, (0.0, 0.0), (math.pi / 2, 0.0), opt)
    assert hit is not None and hit.b.startswith("BAR@")
    # The other way the bar swings down, away from the arm.
    assert move_hit(arm, q, home, pos, (0.0, 0.0), (-math.pi / 2, 0.0), opt) is None
    # No swept point moves more than the step between two samples.
    bodies = swept_bodies(home, pos, (0.0, 0.0), (math.pi / 2, 0.0), 0.02)
    bars = [b for b in bodies if b.name.startswith("BAR@")]
    tips = np.array([b.vertices().max(axis=0) for b in bars])
    assert (
        len(bars) >= math.ceil(1.1 * math.pi / 2 / 0.02)
        and np.max(np.linalg.norm(np.diff(tips, axis=0), axis=1)) < 0.02
    )


def test_a_route_round_the_arm_turns_one_axis_first(arm: RobotModel) -> None:
    """The bar standing up, brought down and turned a quarter: both axes together sweep it through the torch;
    turning it first where it stands and then tilting it down is clear, and that route is taken."""
    pos, home = _bar_beside(arm)
    a, b = (math.pi / 2, 0.0), (0.0, math.pi / 2)
    opt = CollisionOptions()
    assert move_hit(arm, Q_ARM, home, pos, a, b, opt) is not None
    route, hit = clear_route(arm, Q_ARM, home, pos, a, b, opt)
    assert hit is None and route == ((math.pi / 2, math.pi / 2), b)
    # Turned a quarter at the flat, the bar meets the arm's base whichever way it is brought up: refused.
    route, hit = clear_route(arm, Q_ARM, home, pos, (0.0, 0.0), (math.pi / 2, math.pi / 2), opt)
    assert route == () and hit is not None


@pytest.mark.parametrize(
    ("a", "b"),
    [((0.0, 0.0), (math.pi / 2, 0.0)), ((0.0, 0.0), (-math.pi / 2, 0.0)), ((math.pi / 2, 0.0), (0.0, math.pi / 2))],
)
def test_a_sweep_is_checked_against_the_bodies_that_can_touch_the_arm_with_the_same_answer(
    arm: RobotModel, a: tuple[float, float], b: tuple[float, float]
) -> None:
    """The check leaves out the swept samples no arm shape's sphere comes within the clearance of: the contact (or
    none) is the one a collision model of every sample finds, to the pair and the depth."""
    from dataclasses import replace

    pos, home = _bar_beside(arm)
    opt = CollisionOptions()
    grown = replace(opt, part_inflation=opt.part_inflation + 0.01)
    full = CollisionChecker(arm, swept_bodies(home, pos, a, b, 0.02), grown).check(Q_ARM)
    got = move_hit(arm, Q_ARM, home, pos, a, b, opt)
    if full is None:
        assert got is None
    else:
        assert got is not None and (got.a, got.b, got.depth) == (full.a, full.b, full.depth)


def test_the_sphere_gap_is_a_lower_bound_on_each_swept_bodys_clearance(arm: RobotModel) -> None:
    """What lets the sweep's check leave bodies out: each swept sample's gap is at most its clearance to the arm as
    a collision model of that body alone measures it, and some samples are left out."""
    from dataclasses import replace

    from cell.pipeline.positioned.sweep import sphere_gaps, touching

    pos, home = _bar_beside(arm)
    grown = replace(CollisionOptions(), part_inflation=CollisionOptions().part_inflation + 0.01)
    near = swept_bodies(home, pos, (0.0, 0.0), (math.pi / 2, 0.0), 0.02)
    checker = CollisionChecker(arm, (), grown)
    gaps = sphere_gaps(checker, Q_ARM, near)
    clear = np.array([CollisionChecker(arm, [p], grown).clearance(Q_ARM)[0] for p in near])
    assert np.all(gaps <= clear + 1e-9)
    kept = touching(checker, Q_ARM, near)
    assert 0 < len(kept) < len(near)
    assert all(p in kept for p, c in zip(near, clear, strict=True) if c <= grown.min_clearance)
