"""Torch poses from the fillet geometry: work and travel angles, spin, TCP on the seam, process spec units."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cell import scenario as sc
from cell.errors import PlanError, ScenarioError
from cell.geometry import point_line_distance
from cell.process.torch import WeldProcess, back_off, measured_angles, torch_poses, torch_rotation

# A square fillet along +x: face A is the top of the abutting part (+z), face B the wall it meets (+y normal).
D = np.array([1.0, 0.0, 0.0])
N_A = np.array([0.0, 0.0, 1.0])
N_B = np.array([0.0, 1.0, 0.0])
P0, P1 = np.array([0.2, 0.5, 0.1]), np.array([0.28, 0.5, 0.1])
PROCESS = WeldProcess.from_spec(sc.ProcessSpec())


def _angle_to_plane(v: np.ndarray, n: np.ndarray) -> float:
    """Angle [deg] between a direction and a plane of normal n."""
    return math.degrees(math.asin(abs(float(v @ n)) / float(np.linalg.norm(v))))


def test_process_defaults_follow_the_reference_figures() -> None:
    # docs/reference.md section 4: 8-10 mm/s, work 45 deg, travel 5-15 deg, CTWD 12-20 mm; section 7: 250 mm/s.
    assert 0.008 <= PROCESS.travel_speed <= 0.010
    assert math.isclose(math.degrees(PROCESS.work_angle), 45.0)
    assert 5.0 <= math.degrees(PROCESS.travel_angle) <= 15.0
    assert 0.012 <= PROCESS.ctwd <= 0.020
    assert math.isclose(PROCESS.approach_speed, 0.25)
    assert PROCESS.standoff == pytest.approx(0.0)  # the wire tip is on the seam by default


def test_work_angle_bisects_a_square_fillet() -> None:
    R = torch_rotation(D, N_A, N_B, math.radians(45.0), 0.0)
    z = R[:, 2]
    assert _angle_to_plane(z, N_A) == pytest.approx(45.0)
    assert _angle_to_plane(z, N_B) == pytest.approx(45.0)
    np.testing.assert_allclose(z, -(N_A + N_B) / math.sqrt(2.0), atol=1e-12)  # into the joint
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0)


def test_work_angle_is_measured_from_face_b() -> None:
    R = torch_rotation(D, N_A, N_B, math.radians(30.0), 0.0)
    assert _angle_to_plane(R[:, 2], N_B) == pytest.approx(30.0)
    assert _angle_to_plane(R[:, 2], N_A) == pytest.approx(60.0)


@pytest.mark.parametrize("travel_deg", [10.0, -10.0])
def test_travel_angle_sign_push_points_the_wire_ahead(travel_deg: float) -> None:
    X = torch_poses(P0, P1, N_A, N_B, PROCESS, travel_offset=math.radians(travel_deg) - PROCESS.travel_angle)
    z = X[0][:3, 2]
    tilt = math.degrees(math.asin(float(z @ D)))
    assert tilt == pytest.approx(travel_deg)  # push (> 0): wire leans towards the weld direction
    # Welding the other way round flips the lean with the direction, so it is still a push/drag.
    X_rev = torch_poses(P1, P0, N_A, N_B, PROCESS, travel_offset=math.radians(travel_deg) - PROCESS.travel_angle)
    assert math.degrees(math.asin(float(X_rev[0][:3, 2] @ -D))) == pytest.approx(travel_deg)


def test_tcp_lies_on_the_seam_evenly_spaced() -> None:
    X = torch_poses(P0, P1, N_A, N_B, PROCESS, spacing=0.003)
    p = X[:, :3, 3]
    np.testing.assert_allclose(p[0], P0, atol=1e-12)
    np.testing.assert_allclose(p[-1], P1, atol=1e-12)
    assert np.max(point_line_distance(p, P0, P1)) < 1e-12
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    assert np.all(steps <= 0.003 + 1e-12) and np.ptp(steps) < 1e-12
    assert np.allclose(X[:, :3, :3], X[0, :3, :3])  # constant orientation along a straight seam
    assert not X.flags.writeable


def test_longer_contact_tip_distance_stands_the_torch_back() -> None:
    far = WeldProcess.from_spec(sc.ProcessSpec(contact_tip_distance_mm=20.0), stickout_mm=15.0)
    X = torch_poses(P0, P1, N_A, N_B, far)
    # 5 mm back along the torch axis, out of the joint
    np.testing.assert_allclose(X[0][:3, 3], P0 - 0.005 * X[0][:3, 2], atol=1e-12)
    assert float((X[0][:3, 3] - P0) @ (N_A + N_B)) > 0.0


def test_spin_turns_about_the_torch_axis_only() -> None:
    R0 = torch_rotation(D, N_A, N_B, PROCESS.work_angle, PROCESS.travel_angle, 0.0)
    R1 = torch_rotation(D, N_A, N_B, PROCESS.work_angle, PROCESS.travel_angle, math.radians(70.0))
    np.testing.assert_allclose(R1[:, 2], R0[:, 2], atol=1e-12)
    assert math.degrees(math.acos(float(R0[:, 0] @ R1[:, 0]))) == pytest.approx(70.0)


def test_measured_angles_invert_torch_rotation() -> None:
    rng = np.random.default_rng(3)
    for _ in range(20):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        n_b = np.cross(d, rng.normal(size=3))
        n_b /= np.linalg.norm(n_b)
        n_a = np.cross(n_b, d)  # a square fillet along d
        w, a, s = rng.uniform(0.3, 1.2), rng.uniform(-0.4, 0.4), rng.uniform(-math.pi, math.pi)
        X = np.eye(4)
        X[:3, :3] = torch_rotation(d, n_a, n_b, w, a, s)
        assert measured_angles(X, d, n_a, n_b) == pytest.approx((w, a), abs=1e-9)


def test_back_off_moves_out_along_the_torch_axis() -> None:
    X = torch_poses(P0, P1, N_A, N_B, PROCESS)[0]
    Xb = back_off(X, 0.05)
    np.testing.assert_allclose(Xb[:3, 3], X[:3, 3] - 0.05 * X[:3, 2])
    np.testing.assert_allclose(Xb[:3, :3], X[:3, :3])


def test_bad_geometry_is_a_plan_error() -> None:
    with pytest.raises(PlanError, match="parallel"):
        torch_rotation(D, N_B, N_B, 0.7, 0.0)
    with pytest.raises(PlanError, match="non-zero"):
        torch_rotation(D, np.zeros(3), N_B, 0.7, 0.0)
    with pytest.raises(PlanError, match=r"0\.1 mm"):
        torch_poses(P0, P0, N_A, N_B, PROCESS)


def test_process_section_of_a_scenario() -> None:
    text = (sc.SCENARIO_DIR / "fence1.yaml").read_text()
    s = sc.from_yaml(text + "process: {travel_speed_mm_s: 9.5, travel_angle_deg: 12}\n", sc.SCENARIO_DIR)
    p = WeldProcess.from_spec(s.process, s.robot.stickout_mm)
    assert p.travel_speed == pytest.approx(0.0095)
    assert p.travel_angle == pytest.approx(math.radians(12.0))
    with pytest.raises(ScenarioError, match="did you mean 'travel_speed_mm_s'"):
        sc.from_yaml(text + "process: {travel_sped_mm_s: 9}\n", sc.SCENARIO_DIR)
    with pytest.raises(ScenarioError, match="approach_speed_mm_s"):
        sc.from_yaml(text + "process: {approach_speed_mm_s: 400}\n", sc.SCENARIO_DIR)  # above 250 (ISO 10218)
