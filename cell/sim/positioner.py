"""The positioner in the simulator: its bodies (grey boxes: :func:`cell.positioner.bodies.positioner_parts`) and a
rigid move of whatever the faceplate carries (docs/positioner.md, "Sensing and the simulator")."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from scipy.spatial.transform import Rotation

from cell.geometry import FloatArray, make_pose
from cell.sim.bodies import add_part
from cell.sim.quiet import BulletClient
from cell.types import Part

_RGBA = (0.35, 0.38, 0.42, 1.0)


def add_bodies(client: BulletClient, parts_W: Iterable[Part]) -> dict[str, int]:
    """Static bodies for the positioner's boxes in W; name -> body id."""
    return {p.name: add_part(client, p, _RGBA) for p in parts_W}


def move_bodies(client: BulletClient, bodies: Iterable[int], X_W_new_old: FloatArray) -> None:
    """Move each body by the rigid motion X_W_new_old (4, 4) in W."""
    X = np.asarray(X_W_new_old, dtype=float)
    for body in bodies:
        pos, quat = client.getBasePositionAndOrientation(body)
        X_new = X @ make_pose(Rotation.from_quat(quat).as_matrix(), np.asarray(pos, dtype=float))
        q_new = Rotation.from_matrix(X_new[:3, :3]).as_quat()
        client.resetBasePositionAndOrientation(body, [float(v) for v in X_new[:3, 3]], [float(v) for v in q_new])
