"""Joint limits of an arm: position from the URDF; velocity, acceleration and jerk from a YAML file.

The YAML file (see ``robots/kr5_arc.limits.yaml``) maps every joint to ``velocity`` [rad/s], ``acceleration``
[rad/s^2] and ``jerk`` [rad/s^3]. Its velocities may be lower than the URDF's (a slower cell), never higher.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import yaml

from cell.errors import ScenarioError
from cell.geometry import FloatArray
from cell.types.robot import JointLimits

_KEYS = ("velocity", "acceleration", "jerk")


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
