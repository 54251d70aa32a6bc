"""KUKA's Status and Turn of a joint configuration, from the arm's kinematics (the bits: docs/reference.md section
5). The arm is read through :class:`~cell.types.robot.Kinematics` only, so the elbow's angle phi follows the model."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, invert
from cell.types.robot import Kinematics

A1_FRAME, A2_FRAME, A3_FRAME, WRIST_FRAME = "link_1", "link_2", "link_3", "link_5"


@dataclass(frozen=True)
class ArmGeometry:
    """The arm's constants for Status: ``phi`` [rad], the A3 angle of the stretched arm."""

    phi: float

    @classmethod
    def of(cls, robot: Kinematics) -> ArmGeometry:
        """phi from the kinematics: the signed angle, about A3's axis of rotation, that turns the A3-to-wrist
        direction onto the A2-to-A3 direction, at A3 = 0 (the other axes at 0)."""
        q0 = np.zeros(len(robot.joint_names))
        q1 = q0.copy()
        q1[2] = 1e-3
        p2 = robot.fk(q0, A2_FRAME)[:3, 3]
        p3 = robot.fk(q0, A3_FRAME)[:3, 3]
        w0 = robot.fk(q0, WRIST_FRAME)[:3, 3] - p3
        w1 = robot.fk(q1, WRIST_FRAME)[:3, 3] - p3
        axis = np.cross(w0, w1)  # A3's positive rotation direction, from the motion itself
        axis /= np.linalg.norm(axis)
        u = p3 - p2
        return cls(phi=math.atan2(float(np.dot(np.cross(w0, u), axis)), float(np.dot(w0, u))))


def status_turn(robot: Kinematics, q: npt.ArrayLike, geometry: ArmGeometry | None = None) -> tuple[int, int]:
    """(S, T) of the configuration q (6,) [rad] by KUKA's definitions (module docstring)."""
    q = np.asarray(q, dtype=float)
    geo = geometry or ArmGeometry.of(robot)
    p_A1W = (invert(robot.fk(q, A1_FRAME)) @ np.append(robot.fk(q, WRIST_FRAME)[:3, 3], 1.0))[:3]
    s = 1 if p_A1W[0] < 0.0 else 0
    if q[2] >= geo.phi:
        s |= 2
    a5 = math.degrees(q[4])
    if -180.0 <= a5 < 0.0 or a5 >= 180.0:
        s |= 4
    t = sum(1 << i for i, v in enumerate(q[:6]) if v < 0.0)
    return s, t


def status_turn_many(robot: Kinematics, qs: FloatArray) -> list[tuple[int, int]]:
    """(S, T) of each configuration of qs (n, 6) [rad]."""
    geo = ArmGeometry.of(robot)
    return [status_turn(robot, q, geo) for q in np.asarray(qs, dtype=float)]
