"""Joint limits of an arm: position from the URDF; velocity, acceleration and jerk from a YAML file.

The YAML file (see ``robots/kr5_arc.limits.yaml``) maps every joint to ``velocity`` [rad/s], ``acceleration``
[rad/s^2] and ``jerk`` [rad/s^3]. Its velocities may be lower than the URDF's (a slower cell), never higher.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
import yaml

from cell.errors import ScenarioError
from cell.geometry import FloatArray, readonly

_KEYS = ("velocity", "acceleration", "jerk")


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


def load_limits(
    path: Path, names: Sequence[str], q_min: FloatArray, q_max: FloatArray, v_urdf: FloatArray
) -> JointLimits:
    """Read a ``*.limits.yaml`` file for the joints ``names`` (URDF order) and join it with the URDF limits.

    q_min, q_max, v_urdf : (dof,) position [rad] and velocity [rad/s] limits from the URDF.
    Raises ScenarioError when the file is missing or malformed, names a joint the URDF lacks, misses one, or
    allows a joint faster than the URDF does.
    """
    if not path.is_file():
        raise ScenarioError(f"robot limits file {path} not found; it must sit beside the URDF as <name>.limits.yaml")
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ScenarioError(f"robot limits file {path} is not valid YAML: {exc}") from exc
    if not isinstance(data, Mapping) or set(data) != {"joints"} or not isinstance(data["joints"], Mapping):
        raise ScenarioError(f"robot limits file {path} must hold exactly one key 'joints' mapping joint names")
    joints: Mapping[str, object] = data["joints"]
    unknown = sorted(set(joints) - set(names))
    missing = [n for n in names if n not in joints]
    if unknown or missing:
        raise ScenarioError(
            f"robot limits file {path}: unknown joints {unknown}, missing joints {missing}; "
            f"joints of the URDF: {', '.join(names)}"
        )
    table = np.zeros((len(names), 3))
    for i, name in enumerate(names):
        entry = joints[name]
        if not isinstance(entry, Mapping) or set(entry) != set(_KEYS):
            raise ScenarioError(f"robot limits file {path}: joint {name} must give exactly {', '.join(_KEYS)}")
        try:
            table[i] = [float(entry[k]) for k in _KEYS]
        except (TypeError, ValueError) as exc:
            raise ScenarioError(f"robot limits file {path}: joint {name} has a non-numeric limit") from exc
    if not np.all(np.isfinite(table)) or np.any(table <= 0):
        raise ScenarioError(f"robot limits file {path}: every limit must be a positive number")
    too_fast = [n for n, v, vu in zip(names, table[:, 0], v_urdf, strict=True) if v > vu * (1 + 1e-9)]
    if too_fast:
        raise ScenarioError(
            f"robot limits file {path}: velocity of {', '.join(too_fast)} exceeds the URDF's limit; "
            "it may only be lowered"
        )
    return JointLimits(tuple(names), q_min, q_max, table[:, 0], table[:, 1], table[:, 2])
