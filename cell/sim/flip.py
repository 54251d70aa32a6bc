"""The operator turns the part over: where the as-built part, with the beads already on it, comes to
rest after the nominal turn, and how far off the operator sets it down (``simulation.flip_placement``).

Ground truth only: nothing here is handed to perception.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from cell.geometry import FloatArray, make_pose, transform_points
from cell.resting import axis_rotation, set_down
from cell.scenario.flip_specs import FlipPlacementSpec
from cell.types import Part


def body_points(parts_W: Sequence[Part], beads_W: FloatArray, bead_radius_m: float) -> FloatArray:
    """(n, 3) points of the rigid body in W: every part's vertices and each bead capsule's ends grown by its
    radius along the world axes (a bead that sticks out below the part is what it rests on)."""
    pts = [np.concatenate([p.vertices() for p in parts_W])]
    if len(beads_W):
        ends = beads_W.reshape(-1, 3)
        grow = np.concatenate([np.eye(3), -np.eye(3)]) * bead_radius_m
        pts.append((ends[:, None, :] + grow[None, :, :]).reshape(-1, 3))
    return np.concatenate(pts)


def body_volume(part: Part) -> float:
    """The volume [m^3] of a part's body: a box's edge lengths multiplied, a polyhedron's
    from its closed surface (signed tetrahedra from its triangles: :attr:`cell.types.Polyhedron.volume`, whose centre
    of mass :attr:`cell.types.Part.center` is the same sum's centroid)."""
    return float(np.prod(part.box.size)) if part.is_box else float(part.volume)


def operator_error(spec: FlipPlacementSpec, rng: np.random.Generator, centre_W: FloatArray) -> FloatArray:
    """(4, 4) the operator's placement error in W: a turn of ``rotation_deg`` (its sign drawn) about the vertical
    through ``centre_W`` (3,), then a horizontal shift of ``offset_mm`` in a drawn direction."""
    direction = float(rng.uniform(0.0, 2.0 * math.pi))
    sign = 1.0 if rng.uniform() < 0.5 else -1.0
    R = axis_rotation(np.array([0.0, 0.0, 1.0]), sign * math.radians(spec.rotation_deg))
    X = make_pose(R, centre_W - R @ centre_W)
    X[:2, 3] += spec.offset_mm * 1e-3 * np.array([math.cos(direction), math.sin(direction)])
    return X


def turned_pose(
    parts_W: Sequence[Part],
    beads_W: FloatArray,
    bead_radius_m: float,
    X_W_turn: FloatArray,
    table_top_z: float,
    spec: FlipPlacementSpec,
    rng: np.random.Generator,
) -> FloatArray:
    """(4, 4) X_W_new_old: the as-built part moved by the nominal turn X_W_turn (4, 4), settled on its own hull
    (the as-built bodies and the beads differ a little from the drawing), set down on the table top and shifted
    by the operator's error."""
    pts = transform_points(X_W_turn, body_points(parts_W, beads_W, bead_radius_m))
    vol = np.array([body_volume(p) for p in parts_W])
    com = transform_points(X_W_turn, (np.stack([p.center for p in parts_W]) * vol[:, None]).sum(axis=0) / vol.sum())
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    X_settle, _, _ = set_down(pts, com, np.eye(3), centre, table_top_z)
    X = X_settle @ np.asarray(X_W_turn, dtype=float)
    return operator_error(spec, rng, transform_points(X_settle, centre)) @ X
