"""KUKA's Status and Turn from joint values, against configurations worked by hand on the KR 5 arc's dimensions
(A1 frame: A2 axis 180 mm forward and 400 mm up, lower arm 600 mm, A3 to wrist 620 mm along and 120 mm across)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cell.export.status_turn import ArmGeometry, status_turn
from cell.motion.robot import RobotModel

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


def test_phi_is_the_stretched_arm_of_the_a3_a4_offset(robot: RobotModel) -> None:
    # the wrist lies on the line from A2 through A3 when A3 turns the 620 x 120 mm forearm onto it
    assert math.degrees(ArmGeometry.of(robot).phi) == pytest.approx(math.degrees(math.atan2(120.0, 620.0)), abs=1e-6)


@pytest.mark.parametrize(
    ("axes_deg", "s", "t"),
    [
        # KUKA's home: lower arm up, forearm forward, wrist at x = +800 mm: basic area, elbow up (A3 90 >= 10.95),
        # A5 0 counts as positive; only A2 is negative
        ((0, -90, 90, 0, 0, 0), 2, 2),
        ((0, -90, 90, 0, -30, 0), 6, 2 + 16),  # A5 negative: S bit 2 and T bit 4
        ((-90, -100, 100, 0, 45, 0), 2, 1 + 2),  # A1 turns the A1 frame with the arm: still the basic area
        ((180, -90, 90, 0, 0, 0), 2, 2),
        # lower arm leaning back 60 deg (A2 -150): A3 at x = 180 - 520 = -340 mm, the forearm at -130 deg reaches
        # x = -490 mm further: the wrist at -830 mm, the overhead area
        ((0, -150, 20, 0, 0, 0), 1 + 2, 2),
        # A3 5 deg is below phi (10.95 deg): past the stretched arm; the wrist still in front (x = +115 mm)
        ((0, -90, 5, 0, 0, 0), 0, 2),
        ((10, -80, 60, -20, 30, -100), 2, 2 + 8 + 32),
    ],
)
def test_status_and_turn_of_hand_worked_configurations(
    robot: RobotModel, axes_deg: tuple[float, ...], s: int, t: int
) -> None:
    assert status_turn(robot, np.radians(axes_deg)) == (s, t)


def test_a5_beyond_half_a_turn_counts_by_kukas_ranges(robot: RobotModel) -> None:
    base = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])
    for a5, bit2 in ((170.0, 0), (-170.0, 4), (200.0, 4), (-200.0, 0)):
        q = base.copy()
        q[4] = math.radians(a5)
        assert status_turn(robot, q)[0] & 4 == bit2, a5


@pytest.mark.parametrize(
    ("axes_deg", "conf"),
    [
        ((0, -90, 90, 0, 0, 0), "[0,0,0,0]"),  # wrist in front of axis 1 and of the lower arm, axis 5 not negative
        ((-100, -90, 90, 95, -30, -200), "[-2,1,-3,1]"),  # quarter turns floor(angle / 90), axis 5 negative
        ((0, -150, 20, 0, 0, 0), "[0,0,0,4]"),  # the wrist behind axis 1 (the overhead area), still ahead of the arm
        # lower arm leaning 30 deg forward, forearm bent back past its line (A3 -10): the wrist at x = +579 mm,
        # 227 mm behind the lower arm's line
        ((0, -60, -10, 0, 10, 0), "[0,0,0,2]"),
    ],
)
def test_rapid_confdata_of_hand_worked_configurations(
    robot: RobotModel, axes_deg: tuple[float, ...], conf: str
) -> None:
    from cell.export.rapid import confdata

    assert confdata(robot, np.radians(axes_deg)) == conf
