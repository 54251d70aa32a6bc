"""The KR 5 arc model (URDF, limits) and inverse kinematics."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cell.errors import IKError, MotionError, ScenarioError
from cell.geometry import FloatArray, invert, make_pose, rot_y, rot_z
from cell.motion.ik import IKOptions, IKSolveError, solve_ik, solve_path
from cell.motion.robot import RobotModel

ROBOTS = Path(__file__).resolve().parents[2] / "robots"
URDF = ROBOTS / "kr5_arc.urdf"
HOME = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])  # KUKA home: upper arm up, forearm forward

# OPW parameters of the KR 5 arc (ros-industrial/kuka_experimental, kuka_kr5_support) [m], and the published
# mapping
# between KUKA axis values and the OPW angles (opw_kinematics' KUKA examples): theta = sign * q - offset.
A1, A2, B, C1, C2, C3, C4 = 0.180, -0.120, 0.0, 0.400, 0.600, 0.620, 0.115
OPW_SIGN = np.array([-1.0, 1.0, 1.0, -1.0, 1.0, -1.0])
OPW_OFFSET = np.array([0.0, -np.pi / 2.0, 0.0, 0.0, 0.0, 0.0])


def opw_flange(q: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Flange position (3,) and OPW end-effector rotation (3, 3) from the closed form of Brandstoetter et al.
    2014."""
    t = OPW_SIGN * q - OPW_OFFSET
    psi3, k = math.atan2(A2, C3), math.hypot(A2, C3)
    cx1 = C2 * math.sin(t[1]) + k * math.sin(t[1] + t[2] + psi3) + A1
    cz1 = C2 * math.cos(t[1]) + k * math.cos(t[1] + t[2] + psi3)
    c, s = math.cos(t[0]), math.sin(t[0])
    wrist = np.array([cx1 * c - B * s, cx1 * s + B * c, cz1 + C1])
    R = rot_z(t[0]) @ rot_y(t[1] + t[2]) @ rot_z(t[3]) @ rot_y(t[4]) @ rot_z(t[5])
    return wrist + C4 * R[:, 2], R


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def _rot_err_deg(X_a: FloatArray, X_b: FloatArray) -> float:
    R = X_a[:3, :3].T @ X_b[:3, :3]
    return math.degrees(math.acos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)))


def test_generated_files_are_up_to_date() -> None:
    # The URDF and limits file are generated; a hand edit (or a script edit without a rerun) is caught here.
    run = subprocess.run(
        [sys.executable, str(ROBOTS / "build_kr5_arc.py"), "--check"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stdout + run.stderr


def test_fk_matches_opw_closed_form(robot: RobotModel) -> None:
    # tool0 = $FLANGE has x out of the flange; OPW's end frame has z out of it: R_tool0 = R_opw @ Ry(-90 deg).
    rng = np.random.default_rng(3)
    qs = [np.zeros(6), HOME] + [robot.limits.sample(rng) for _ in range(6)]
    for q in qs:
        X = robot.fk(q, "tool0")
        p, R = opw_flange(q)
        np.testing.assert_allclose(X[:3, 3], p, atol=1e-9)
        np.testing.assert_allclose(X[:3, :3], R @ rot_y(-np.pi / 2.0), atol=1e-9)
    # Zero joints: arm stretched forward; KUKA home: the OPW zero pose with the forearm lowered by 90 deg.
    np.testing.assert_allclose(robot.fk(np.zeros(6), "tool0")[:3, 3], [A1 + C2 + C3 + C4, 0.0, C1 - A2], atol=1e-12)
    np.testing.assert_allclose(robot.fk(HOME, "tool0")[:3, 3], [A1 + C3 + C4, 0.0, C1 + C2 - A2], atol=1e-12)


def test_joint_names_and_limits(robot: RobotModel) -> None:
    lim = robot.limits
    assert robot.joint_names == tuple(f"joint_a{i}" for i in range(1, 7))
    np.testing.assert_allclose(np.degrees(lim.q_min), [-155, -180, -15, -350, -130, -350])
    np.testing.assert_allclose(np.degrees(lim.q_max), [155, 65, 158, 350, 130, 350])
    np.testing.assert_allclose(np.degrees(lim.v_max), [154, 154, 228, 343, 384, 721])
    assert np.all(lim.a_max > lim.v_max) and np.all(lim.j_max > lim.a_max)
    with pytest.raises(ValueError):
        lim.q_min[0] = 0.0  # read-only


def test_torch_and_camera_frames(robot: RobotModel) -> None:
    X = robot.fk_frames(HOME, ("tool0", "torch_tcp", "camera_link", "camera_optical"))
    X_0T = invert(X["tool0"]) @ X["torch_tcp"]
    assert 0.35 <= np.linalg.norm(X_0T[:3, 3]) <= 0.40
    # The wire (TCP z) leaves the torch: pointing away from the flange, bent 22 deg from the flange axis.
    assert math.degrees(math.acos(X_0T[0, 2])) == pytest.approx(22.0, abs=1e-6)
    assert X_0T[:3, 3] @ X_0T[:3, 2] > 0.3
    # Optical frame: z forward = camera_link x, x right = -camera_link y, y down = -camera_link z.
    R_LO = X["camera_link"][:3, :3].T @ X["camera_optical"][:3, :3]
    np.testing.assert_allclose(R_LO, [[0, 0, 1], [-1, 0, 0], [0, -1, 0]], atol=1e-10)
    # The camera looks roughly along the torch and sees the wire tip in front of it, near the image centre.
    X_OT = invert(X["camera_optical"]) @ X["torch_tcp"]
    assert 0.15 < X_OT[2, 3] < 0.6
    assert math.degrees(math.atan2(np.linalg.norm(X_OT[:2, 3]), X_OT[2, 3])) < 10.0
    z_opt_in_tool0 = (invert(X["tool0"]) @ X["camera_optical"])[:3, 2]
    assert math.degrees(math.acos(z_opt_in_tool0[0])) < 35.0


def test_pybullet_loads_the_same_kinematics(robot: RobotModel) -> None:
    import pybullet
    from pybullet_utils.bullet_client import BulletClient

    client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        body = client.loadURDF(str(URDF), useFixedBase=True)
        infos = [client.getJointInfo(body, i) for i in range(client.getNumJoints(body))]
        links = {info[12].decode(): info[0] for info in infos}
        movable = [info[1].decode() for info in infos if info[2] == pybullet.JOINT_REVOLUTE]
        assert movable == list(robot.joint_names)
        assert {"tool0", "torch", "torch_tcp", "camera_link", "camera_optical"} <= set(links)
        q = np.radians([20.0, -70.0, 110.0, 30.0, 40.0, -50.0])
        for name, value in zip(robot.joint_names, q, strict=True):
            index = next(info[0] for info in infos if info[1].decode() == name)
            client.resetJointState(body, index, float(value))
        for frame in ("tool0", "torch_tcp", "camera_optical"):
            state = client.getLinkState(body, links[frame], computeForwardKinematics=True)
            R = np.array(client.getMatrixFromQuaternion(state[5])).reshape(3, 3)
            X = robot.fk(q, frame)
            np.testing.assert_allclose(state[4], X[:3, 3], atol=1e-6)
            np.testing.assert_allclose(R, X[:3, :3], atol=1e-6)
    finally:
        client.disconnect()


def test_unknown_frame_lists_the_valid_ones(robot: RobotModel) -> None:
    with pytest.raises(MotionError, match="torch_tcp"):
        robot.fk(HOME, "torch_tip")


def test_jacobian_matches_finite_differences(robot: RobotModel) -> None:
    q = np.radians([10.0, -60.0, 100.0, 20.0, 50.0, -30.0])
    J = robot.jacobian(q, "torch_tcp", "aligned")
    X0, h = robot.fk(q), 1e-6
    for i in range(6):
        dq = np.zeros(6)
        dq[i] = h
        X1 = robot.fk(q + dq)
        np.testing.assert_allclose((X1[:3, 3] - X0[:3, 3]) / h, J[:3, i], atol=1e-5)
        dR = (X1[:3, :3] - X0[:3, :3]) / h @ X0[:3, :3].T  # skew(omega)
        np.testing.assert_allclose([dR[2, 1], dR[0, 2], dR[1, 0]], J[3:, i], atol=1e-5)


def test_manipulability_vanishes_at_the_wrist_singularity(robot: RobotModel) -> None:
    # Relative to the problem's own scale: the Jacobian's smallest singular value over its largest (its inverse
    # condition number), never an absolute bar on a product of floats (sqrt(det) near 1e-17 is rounding noise).
    def inverse_condition(q: np.ndarray) -> float:
        s = np.linalg.svd(robot.jacobian(q, "tool0", "aligned"), compute_uv=False)
        return float(s[-1] / s[0])

    q = np.radians([10.0, -60.0, 100.0, 20.0, 50.0, -30.0])
    w_regular, k_regular = robot.manipulability(q), inverse_condition(q)  # measured 0.30 m^3, 0.17
    assert w_regular > 1e-2 and k_regular > 0.05
    q[4] = 0.0  # A5 = 0: A4 and A6 aligned
    assert inverse_condition(q) < 1e-6 * k_regular  # measured 2.5e-18
    assert robot.manipulability(q) < 1e-6 * w_regular  # 0 here; 6.4e-9 seen where det(J J^T) rounds to 4e-17


def test_ik_round_trip_from_perturbed_seeds(robot: RobotModel) -> None:
    rng = np.random.default_rng(7)
    solved = 0
    while solved < 60:
        q = robot.limits.sample(rng, margin=np.radians(5.0))
        if robot.manipulability(q) < 0.02:  # keep away from singularities
            continue
        X = robot.fk(q)
        q_ik = solve_ik(robot, X, q + rng.normal(0.0, 0.05, 6))
        X_ik = robot.fk(q_ik)
        assert np.linalg.norm(X_ik[:3, 3] - X[:3, 3]) <= 1e-5
        assert _rot_err_deg(X_ik, X) <= 0.01
        assert robot.limits.contains(q_ik) and not q_ik.flags.writeable
        solved += 1


def test_ik_cold_start_with_restarts(robot: RobotModel) -> None:
    q = np.radians([-40.0, -100.0, 120.0, 60.0, -45.0, 30.0])
    X = robot.fk(q)
    q_ik = solve_ik(robot, X, np.zeros(6), rng=np.random.default_rng(0))
    assert np.linalg.norm(robot.fk(q_ik)[:3, 3] - X[:3, 3]) <= 1e-5


def test_ik_unreachable_target_raises(robot: RobotModel) -> None:
    X = make_pose(p=[3.0, 0.0, 0.4])
    with pytest.raises(IKSolveError) as far:
        solve_ik(robot, X, HOME, rng=np.random.default_rng(0))
    assert far.value.beyond_reach and far.value.frame == "torch_tcp"
    np.testing.assert_array_equal(far.value.target, X)
    p_RJ, reach = robot.reach_bound()
    assert far.value.residual_m == pytest.approx(np.linalg.norm(X[:3, 3] - p_RJ) - reach)
    # Within the reach bound but beyond the real workspace: the solver itself must give up, saying how close
    # it got.
    X = make_pose(rot_y(np.pi / 2.0), p=[1.85, 0.0, 0.9])
    with pytest.raises(IKSolveError, match="best error") as near:
        solve_ik(robot, X, HOME, rng=np.random.default_rng(0))
    assert isinstance(near.value, IKError) and not near.value.beyond_reach
    assert near.value.residual_m > IKOptions().pos_tol and np.isfinite(near.value.residual_rad)


def _wrist_centre_distance(X_RT: FloatArray, X_0T: FloatArray) -> float:
    """Distance from the A2 axis of the wrist centre that a TCP pose X_RT implies (front A1 branch) [m]."""
    X_R0 = X_RT @ invert(X_0T)
    p = X_R0[:3, 3] - C4 * X_R0[:3, 0]
    return math.hypot(math.hypot(p[0], p[1]) - A1, p[2] - C1)


def test_free_axis_reaches_a_pose_whose_rotation_is_unreachable(robot: RobotModel) -> None:
    X_0T = invert(robot.fk(HOME, "tool0")) @ robot.fk(HOME, "torch_tcp")
    X = make_pose(np.diag([1.0, -1.0, -1.0]), [1.35, 0.0, -0.2])  # wire straight down, far in front
    # Proof that the full pose is unreachable: its wrist centre lies beyond upper arm + forearm from the A2
    # axis.
    assert _wrist_centre_distance(X, X_0T) > C2 + math.hypot(A2, C3) + 0.05
    with pytest.raises(IKError):
        solve_ik(robot, X, HOME, rng=np.random.default_rng(0))
    q = solve_ik(robot, X, HOME, free_axis=True, rng=np.random.default_rng(0))
    X_ik = robot.fk(q)
    assert np.linalg.norm(X_ik[:3, 3] - X[:3, 3]) <= 1e-5
    assert math.degrees(math.acos(np.clip(X_ik[:3, 2] @ X[:3, 2], -1.0, 1.0))) <= 0.01
    assert _wrist_centre_distance(X_ik, X_0T) <= C2 + math.hypot(A2, C3)


def _seam_targets(robot: RobotModel, n: int) -> FloatArray:
    """Torch poses along a 0.2 m straight line, wire tilted 45 deg, in R."""
    R = rot_z(np.pi / 2.0) @ rot_y(np.pi - np.pi / 4.0)
    return np.array([make_pose(R, [1.0, -0.1 + 0.2 * i / (n - 1), 0.0]) for i in range(n)])


def test_solve_path_warm_starts_along_a_seam(robot: RobotModel) -> None:
    targets = _seam_targets(robot, 101)
    qs = solve_path(robot, targets, HOME, rng=np.random.default_rng(0))
    assert qs.shape == (101, 6) and not qs.flags.writeable
    assert np.max(np.abs(np.diff(qs, axis=0))) < np.radians(2.0)
    for q, X in zip(qs[::10], targets[::10], strict=True):
        assert np.linalg.norm(robot.fk(q)[:3, 3] - X[:3, 3]) <= 1e-5


def test_solve_path_reports_a_configuration_flip(robot: RobotModel) -> None:
    targets = _seam_targets(robot, 11)
    targets[6:, :3, :3] = targets[6:, :3, :3] @ rot_z(np.pi)  # the torch turns half a turn between poses 5 and 6
    with pytest.raises(IKError, match="pose 6 of 11: joint joint_a"):
        solve_path(robot, targets, HOME, rng=np.random.default_rng(0))


def test_solve_path_keeps_the_failure_fields(robot: RobotModel) -> None:
    targets = _seam_targets(robot, 3)
    targets[2, :3, 3] = [3.0, 0.0, 0.4]  # beyond the reach bound
    with pytest.raises(IKSolveError, match="pose 2 of 3: ") as err:
        solve_path(robot, targets, HOME, rng=np.random.default_rng(0))
    assert err.value.beyond_reach
    np.testing.assert_array_equal(err.value.target, targets[2])


def test_limits_file_errors(tmp_path: Path) -> None:
    urdf = tmp_path / "arm.urdf"
    shutil.copy(URDF, urdf)
    with pytest.raises(ScenarioError, match="not found"):
        RobotModel.from_urdf(urdf)
    text = (ROBOTS / "kr5_arc.limits.yaml").read_text()
    (tmp_path / "arm.limits.yaml").write_text(text.replace("joint_a6:", "joint_a7:"))
    with pytest.raises(ScenarioError, match="joint_a7"):
        RobotModel.from_urdf(urdf)
    (tmp_path / "arm.limits.yaml").write_text(re.sub(r"velocity: [0-9.]+", "velocity: 30.0", text, count=1))
    with pytest.raises(ScenarioError, match="exceeds"):
        RobotModel.from_urdf(urdf)


def test_pose_residual_at_is_the_two_calls_to_the_bit(robot: RobotModel) -> None:
    # The IK's one-call kinematics: the same numbers as pose_and_jacobian then pose_residual, bit for bit.
    rng = np.random.default_rng(3)
    fid = robot.frame_id("torch_tcp")
    for _ in range(5):
        q, q_t = robot.limits.sample(rng), robot.limits.sample(rng)
        X_RT = robot.fk(q_t)
        X_RF, J_F = robot.pose_and_jacobian(q, fid)
        e, J = robot.pose_residual(X_RF, X_RT, J_F)
        got = robot.pose_residual_at(q, fid, X_RT)
        for a, b in zip(got, (X_RF, e, J), strict=True):
            np.testing.assert_array_equal(a, b)


def test_the_damped_step_is_numpys_public_solve_to_the_bit() -> None:
    """The damped step calls numpy's private LAPACK kernel to skip the public wrapper's dispatch: it must stay the
    same numbers as ``np.linalg.solve`` (a numpy upgrade that changes the kernel fails here, not in the plans)."""
    from cell.motion.ik import _dls_step

    rng = np.random.default_rng(5)
    for rows in (5, 6):
        eye = np.eye(rows)
        for _ in range(50):
            J, e = rng.normal(size=(rows, 6)), rng.normal(size=rows)
            public = J.T @ np.linalg.solve(J @ J.T + 1e-6 * eye, e)
            assert np.array_equal(_dls_step(J, e, eye, 1e-6), public)
