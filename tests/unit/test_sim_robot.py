"""The arm in the simulated cell (cell.sim.robot via SimCell): poses by name, playback, bead, eye-in-hand camera."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from cell import scenario as scn
from cell.errors import PlanError, ScenarioError, SensorError
from cell.geometry import FloatArray, make_pose, pose_from_xyz_rpy
from cell.motion.robot import RobotModel
from cell.scenario import REPO_ROOT
from cell.sim import SimCell
from cell.types import Box, Part

URDF = REPO_ROOT / "robots" / "kr5_arc.urdf"
# Base beside the table, turned and slightly tilted so that a quaternion order mistake cannot hide.
X_WR = pose_from_xyz_rpy([-0.9, 0.05, 0.5], [math.radians(4.0), math.radians(-3.0), math.radians(20.0)])
Q_LOOK = np.radians([20.0, -90.0, 90.0, 0.0, 45.0, 0.0])  # camera looks down at the table
Q_AWAY = np.radians([180.0, -90.0, 90.0, 0.0, 0.0, 0.0])  # arm turned away from the table
BOX = Box(make_pose(p=[0.2, 0.0, 0.95]), np.array([0.3, 0.1, 0.1]))
LINKS = ("base_link", "link_2", "link_4", "tool0", "torch_tcp", "camera_optical")

TINY = """
name: tiny_robot
seed: 3
simulation: {noise: none}
map: {file: dummy.dxf}
table: {center_m: [0.0, 0.0, 0.85], size_m: [1.2, 0.8, 0.1]}
cameras:
  fixed: {eye_m: [-0.3, 0.0, 1.9], target_m: [0.3, 0.0, 0.9], resolution: [160, 120], hfov_deg: 50}
  hand: {mount: eye_in_hand, eye_m: [0.0, 0.0, 2.0], target_m: [0.0, 0.0, 0.9], resolution: [160, 120]}
perception:
  workspace: {min_m: [-1.0, -1.0, 0.9], max_m: [1.0, 1.0, 1.5]}
"""


@pytest.fixture(scope="module")
def model() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture
def tiny(tmp_path: Path) -> scn.Scenario:
    (tmp_path / "dummy.dxf").write_text("not read by these tests\n")
    return scn.from_yaml(TINY, base_dir=tmp_path)


@pytest.fixture
def sim(tiny: scn.Scenario, model: RobotModel) -> Iterator[SimCell]:
    with SimCell(tiny, [Part("BOX", BOX)]) as cell:
        cell.load_robot(URDF, X_WR, Q_LOOK, joint_names=model.joint_names)
        yield cell


def random_q(model: RobotModel, rng: np.random.Generator) -> FloatArray:
    lo, hi = model.limits.q_min, model.limits.q_max
    return rng.uniform(lo, hi)


def test_link_poses_match_pinocchio_fk(sim: SimCell, model: RobotModel) -> None:
    rng = np.random.default_rng(11)
    for q in [Q_LOOK, np.zeros(6), *(random_q(model, rng) for _ in range(4))]:
        sim.set_q(q)
        np.testing.assert_allclose(sim.robot.q, q, atol=1e-12)
        fk = model.fk_frames(q, LINKS)
        for link in LINKS:
            np.testing.assert_allclose(sim.link_pose(link), X_WR @ fk[link], atol=1e-6, err_msg=link)


def test_robot_loading_errors(sim: SimCell, tiny: scn.Scenario, tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match="already loaded"):
        sim.load_robot(URDF, X_WR, Q_LOOK)
    with pytest.raises(KeyError, match="torch_tcp"):
        sim.link_pose("no_such_link")
    with pytest.raises(ValueError, match="6 finite"):
        sim.set_q(np.zeros(5))
    with SimCell(tiny, []) as empty:
        with pytest.raises(ScenarioError, match="no robot"):
            empty.set_q(Q_LOOK)
        with pytest.raises(ScenarioError, match="not found"):
            empty.load_robot(tmp_path / "missing.urdf", X_WR, Q_LOOK)
        with pytest.raises(ScenarioError, match="movable joints"):
            empty.load_robot(URDF, X_WR, Q_LOOK, joint_names=["joint_a1", "joint_a2"])
        empty.load_robot(URDF, X_WR, Q_LOOK)
    with pytest.raises(SensorError, match="closed"):
        empty.set_q(Q_LOOK)


def sweep(duration: float = 2.0, dt: float = 0.004) -> tuple[FloatArray, FloatArray]:
    """A smooth synthetic trajectory: A1 turns steadily (the tool never revisits a place), the wrist nods."""
    t = np.append(np.arange(0.0, duration, dt), duration)
    q = np.tile(Q_LOOK, (len(t), 1))
    q[:, 0] += 0.4 * t / duration
    q[:, 4] += 0.1 * np.sin(2.0 * np.pi * t / duration)
    return t, q


def test_execute_records_fk_path_and_arc_events(sim: SimCell, model: RobotModel) -> None:
    t, q = sweep()
    arc = (t >= 0.5) & (t < 1.2)
    ex = sim.execute(t, q, arc, record_dt=0.01, marks=[(0.4, "approach seam S1")])

    assert ex.times[0] == 0.0 and ex.times[-1] == 2.0
    assert np.all(np.diff(ex.times) <= 0.01 + 1e-12) and np.all(np.diff(ex.times) > 0.0)
    # played joint values are the input interpolated at the record times
    np.testing.assert_allclose(ex.q, np.column_stack([np.interp(ex.times, t, c) for c in q.T]), atol=1e-12)
    # PyBullet's tool path equals Pinocchio's FK of the same joint values
    fk_W = np.array([X_WR @ model.fk(qk, "torch_tcp") for qk in ex.q])
    assert ex.X_W_tcp is not None
    np.testing.assert_allclose(ex.X_W_tcp, fk_W, atol=1e-6)
    np.testing.assert_allclose(ex.tcp_W, fk_W[:, :3, 3], atol=1e-6)
    np.testing.assert_allclose(sim.robot.q, q[-1], atol=1e-12)  # the arm stays at the end

    kinds = [(round(e.t, 9), e.kind) for e in ex.events]
    assert kinds == [(0.0, "move"), (0.4, "move"), (0.5, "arc_on"), (1.2, "arc_off")]
    assert "approach seam S1" in ex.events[1].detail
    np.testing.assert_array_equal(ex.arc_on, (ex.times >= 0.5 - 1e-9) & (ex.times < 1.2 - 1e-9))
    assert ex.arc_time == pytest.approx(0.7, abs=1e-9)


def distance_to_polyline(points: FloatArray, path: FloatArray) -> FloatArray:
    """Distance [m] of each point (n, 3) from the polyline through path (k, 3)."""
    a, d = path[:-1], np.diff(path, axis=0)  # (k-1, 3)
    v = points[:, None, :] - a[None]  # (n, k-1, 3)
    s = np.clip(np.sum(v * d, axis=2) / np.maximum(np.sum(d * d, axis=1), 1e-30), 0.0, 1.0)
    return np.asarray(np.min(np.linalg.norm(v - s[..., None] * d, axis=2), axis=1))


def test_bead_only_where_the_arc_was_on(sim: SimCell) -> None:
    t, q = sweep()
    arc = (t >= 0.5) & (t < 1.2)
    ex = sim.execute(t, q, arc)
    segs = sim.bead_segments()
    assert len(segs) >= 5
    on = (ex.times >= 0.5) & (ex.times <= 1.2)
    welded, idle = ex.tcp_W[on], ex.tcp_W[(ex.times < 0.45) | (ex.times > 1.25)]
    ends = segs.reshape(-1, 3)

    assert distance_to_polyline(ends, welded).max() < 1e-9  # chord ends lie on the welded path
    assert np.min(np.linalg.norm(ends[:, None] - idle[None], axis=2)) > 0.01  # nowhere near the idle path
    bead_len = float(np.sum(np.linalg.norm(segs[:, 1] - segs[:, 0], axis=1)))
    assert bead_len == pytest.approx(ex.weld_length, rel=1e-3)
    # a move with the arc off draws nothing; clear_beads removes them
    sim.execute(t, q[::-1].copy(), np.zeros(len(t), bool))
    assert len(sim.bead_segments()) == len(segs)
    sim.clear_beads()
    assert len(sim.bead_segments()) == 0


def test_arc_left_on_is_switched_off_at_the_end(sim: SimCell) -> None:
    t, q = sweep(1.0)
    ex = sim.execute(t, q, t >= 0.3, bead=None)
    assert [e.kind for e in ex.events] == ["move", "arc_on", "arc_off"]
    assert ex.events[-1].t == 1.0 and "end of trajectory" in ex.events[-1].detail
    assert len(sim.bead_segments()) == 0


def test_execute_rejects_bad_input(sim: SimCell) -> None:
    t, q = sweep(0.5)
    off = np.zeros(len(t), bool)
    with pytest.raises(ValueError, match="strictly increasing"):
        sim.execute(t[::-1], q, off)
    with pytest.raises(ValueError, match="q must be"):
        sim.execute(t, q[:, :5], off)
    with pytest.raises(ValueError, match="arc_on"):
        sim.execute(t, q, off.astype(int))
    q_bad = q.copy()
    q_bad[-1, 2] = math.radians(170.0)  # A3 allows -15..158 deg
    with pytest.raises(PlanError, match="joint_a3"):
        sim.execute(t, q_bad, off)


def test_eye_in_hand_camera_follows_the_arm(sim: SimCell) -> None:
    first = sim.capture("hand")  # an eye-in-hand camera renders from the arm's camera_optical link
    np.testing.assert_allclose(first.X_WC, sim.link_pose("camera_optical"), atol=1e-12)
    np.testing.assert_array_equal(first.depth, sim.capture_from_link("hand").depth)
    assert np.mean(first.depth > 0) > 0.9  # it looks down at the table
    sim.set_q(Q_LOOK + np.radians([8.0, 0.0, 0.0, 0.0, -10.0, 0.0]))
    moved = sim.capture("hand")
    assert not np.allclose(moved.X_WC, first.X_WC)
    valid = (moved.depth > 0) & (first.depth > 0)
    assert np.mean(np.abs(moved.depth - first.depth)[valid] > 0.005) > 0.3


def test_fixed_camera_unchanged_by_an_arm_out_of_view(tiny: scn.Scenario) -> None:
    with SimCell(tiny, [Part("BOX", BOX)]) as cell:
        before = cell.capture("fixed").depth
        cell.load_robot(URDF, X_WR, Q_AWAY)
        after_away = cell.capture("fixed").depth
        cell.set_q(Q_LOOK)
        after_look = cell.capture("fixed").depth
    np.testing.assert_array_equal(after_away, before)
    assert np.any(after_look != before)  # reaching over the table, the arm is seen (as a real one would be)
