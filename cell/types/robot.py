"""The robot as the vocabulary sees it: its joint limits, and the kinematics a consumer of a plan may ask for.

:class:`Kinematics` is what an exporter or a picture needs of an arm (forward kinematics by frame name);
:class:`cell.motion.robot.RobotModel` (Pinocchio) provides it. Radians, metres, seconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, readonly


class Kinematics(Protocol):
    """Forward kinematics of an arm: ``fk(q, frame)`` is X_RF (4, 4), the pose of frame ``frame`` in the robot base
    R at joint values q (dof,) [rad]."""

    @property
    def joint_names(self) -> tuple[str, ...]: ...

    def fk(self, q: npt.ArrayLike, frame: str = "torch_tcp") -> FloatArray: ...


@dataclass(frozen=True)
class JointLimits:
    """Per-joint limits, all arrays (dof,) and read-only.

    q_min, q_max : position range [rad].
    v_max [rad/s], a_max [rad/s^2], j_max [rad/s^3] : positive magnitudes.
    """

    names: tuple[str, ...]
    q_min: FloatArray
    q_max: FloatArray
    v_max: FloatArray
    a_max: FloatArray
    j_max: FloatArray

    def __post_init__(self) -> None:
        n = len(self.names)
        for key in ("q_min", "q_max", "v_max", "a_max", "j_max"):
            arr = readonly(getattr(self, key))
            if arr.shape != (n,) or not np.all(np.isfinite(arr)):
                raise ValueError(f"JointLimits.{key} must be {n} finite values (one per joint), got {arr.shape}")
            object.__setattr__(self, key, arr)
        if np.any(self.q_min >= self.q_max):
            raise ValueError("JointLimits: q_min must be below q_max for every joint")
        if np.any(self.v_max <= 0) or np.any(self.a_max <= 0) or np.any(self.j_max <= 0):
            raise ValueError("JointLimits: velocity, acceleration and jerk limits must be positive")

    @property
    def dof(self) -> int:
        return len(self.names)

    def contains(self, q: npt.ArrayLike, tol: float = 1e-9) -> bool:
        """Whether the configuration (dof,) lies within the position limits widened by ``tol`` [rad]."""
        q = np.asarray(q, dtype=float)
        return bool(np.all(q >= self.q_min - tol) and np.all(q <= self.q_max + tol))

    def clip(self, q: npt.ArrayLike) -> FloatArray:
        """The configuration (dof,) or (n, dof) clamped into the position limits."""
        return np.clip(np.asarray(q, dtype=float), self.q_min, self.q_max)

    def sample(self, rng: np.random.Generator, margin: float = 0.0) -> FloatArray:
        """A configuration (dof,) drawn uniformly within the limits shrunk by ``margin`` [rad] at each end."""
        lo, hi = self.q_min + margin, self.q_max - margin
        if np.any(lo >= hi):
            raise ValueError(f"JointLimits.sample: margin {margin} rad leaves no room within the position limits")
        return rng.uniform(lo, hi)

    def scaled(self, velocity: float = 1.0, acceleration: float = 1.0, jerk: float = 1.0) -> JointLimits:
        """The same limits with v_max, a_max, j_max multiplied by factors in (0, 1] (a slower motion)."""
        for name, f in (("velocity", velocity), ("acceleration", acceleration), ("jerk", jerk)):
            if not 0.0 < f <= 1.0:
                raise ValueError(f"JointLimits.scaled: {name} factor must be in (0, 1], got {f}")
        return JointLimits(
            self.names,
            self.q_min,
            self.q_max,
            self.v_max * velocity,
            self.a_max * acceleration,
            self.j_max * jerk,
        )
