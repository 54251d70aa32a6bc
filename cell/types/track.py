"""A linear track under the robot base (an external axis E1), as a value, numpy only. Frames: R is the base at E1 = 0,
Re the base at E1 = e, X_R_Re = translation(e * axis_R) (docs/track.md, "Frames"). Units: E1 [m], [m/s], [m/s^2],
[m/s^3] inside; the KRL field E1 is in mm."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.geometry import FloatArray, readonly


@dataclass(frozen=True)
class LinearTrack:
    """The track: unit direction axis_R (3,) in R along which the base moves, E1 limits [e1_min, e1_max] [m]
    (0 inside them: the base at R), and the carriage's speed v_max [m/s], acceleration a_max [m/s^2] and jerk
    j_max [m/s^3] limits."""

    axis_R: FloatArray
    e1_min: float
    e1_max: float
    v_max: float
    a_max: float
    j_max: float

    def __post_init__(self) -> None:
        axis = np.asarray(self.axis_R, dtype=float)
        norm = float(np.linalg.norm(axis))
        if axis.shape != (3,) or not np.isfinite(norm) or norm < 1e-9:
            raise ValueError(f"LinearTrack: axis_R must be 3 finite values, not all zero; got {self.axis_R}")
        object.__setattr__(self, "axis_R", readonly(axis / norm))
        if not self.e1_min <= 0.0 <= self.e1_max:
            raise ValueError(f"LinearTrack: E1 limits [{self.e1_min}, {self.e1_max}] m must hold 0 (the base at R)")
        if min(self.v_max, self.a_max, self.j_max) <= 0.0:
            raise ValueError("LinearTrack: speed, acceleration and jerk limits must be positive")

    @property
    def length(self) -> float:
        """Travel [m] from one end to the other."""
        return self.e1_max - self.e1_min

    def offset_R(self, e1: float) -> FloatArray:
        """(3,) [m]: where the base origin is in R at E1 = e1 [m]."""
        return np.asarray(e1 * self.axis_R, dtype=float)

    def X_R_Re(self, e1: float) -> FloatArray:
        """(4, 4): the base at E1 = e1 [m] in R (a translation along the axis)."""
        X = np.eye(4)
        X[:3, 3] = self.offset_R(e1)
        return X

    def contains(self, e1: float, tol: float = 1e-9) -> bool:
        return self.e1_min - tol <= e1 <= self.e1_max + tol
