"""A positioner move checked against the arm (docs/positioner.md, "The load and the moves"): the part, its
fixtures, the clamping table and the positioner's tilting bodies swept from one pose to the next, sampled so that no
point of them travels more than ``STEP_M`` between samples, each sample grown by half that, and the arm where it
stands checked against the union. Frames: R [m]; axes [rad]."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from cell.config.motion import CollisionOptions
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker, Contact
from cell.motion.robot import RobotModel
from cell.pipeline.positioned.carry import posed_obstacles
from cell.pipeline.records import Detection
from cell.positioner.bodies import PEDESTAL, positioner_parts
from cell.types import Part
from cell.types.positioner import TiltRotatePositioner

STEP_M = 0.02  # [m] the most any swept point travels between two samples


def clamped(det: Detection, pos: TiltRotatePositioner) -> tuple[Part, ...]:
    """What the faceplate carries, in R at home: the aligned map's parts and fixtures and the clamping table."""
    return tuple(p for p in posed_obstacles(det, pos, pos.home, np.eye(4)) if not p.name.startswith("POSITIONER_"))


def swept_bodies(
    home: Sequence[Part],
    pos: TiltRotatePositioner,
    a: tuple[float, float],
    b: tuple[float, float],
    step_m: float = STEP_M,
) -> tuple[Part, ...]:
    """The bodies ``home`` (in R, clamped on the faceplate, where they lie at the positioner's home) and the
    positioner's tilting bodies at samples of the move from axes ``a`` to ``b`` (tilt, rotate) [rad], along the
    straight line between them in the axes' space (both axes synchronised), in R; the still pedestal once."""
    out = [p for p in positioner_parts(pos, *a) if p.name == PEDESTAL]
    for k, (t, r) in enumerate(_samples(home, pos, a, b, step_m)):
        X = pos.move(t, r)
        moving = [*(p.transformed(X) for p in home), *(p for p in positioner_parts(pos, t, r) if p.name != PEDESTAL)]
        out.extend(replace(p, name=f"{p.name}@{k}") for p in moving)
    return tuple(out)


def _samples(
    home: Sequence[Part], pos: TiltRotatePositioner, a: tuple[float, float], b: tuple[float, float], step_m: float
) -> list[tuple[float, float]]:
    """The axes (tilt, rotate) [rad] of :func:`swept_bodies`' samples of the move from ``a`` to ``b``: evenly along
    the straight line in the axes' space, so that no point of ``home`` travels more than ``step_m`` between two."""
    centre = pos.X_R_tilt(0.0)[:3, 3]
    reach = max(float(np.max(np.linalg.norm(p.vertices() - centre, axis=1))) for p in home)
    turn = abs(b[0] - a[0]) + abs(b[1] - a[1])  # an upper bound on the angle any point turns [rad]
    n = max(1, math.ceil(reach * turn / step_m))
    return [(a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])) for s in np.linspace(0.0, 1.0, n + 1)]


def move_hit(
    model: RobotModel,
    q: FloatArray,
    home: Sequence[Part],
    pos: TiltRotatePositioner,
    a: tuple[float, float],
    b: tuple[float, float],
    options: CollisionOptions,
    step_m: float = STEP_M,
) -> Contact | None:
    """Where the arm at ``q`` (dof,) [rad] meets what the positioner's move from ``a`` to ``b`` sweeps of the
    clamped bodies ``home`` (:func:`swept_bodies`; the samples grown by half a step on top of the parts'
    inflation); None when it is clear."""
    if np.allclose(a, b):
        return None
    grown = replace(options, part_inflation=options.part_inflation + step_m / 2.0)
    arm = CollisionChecker(model, (), grown)
    touch = _touching_sweep(arm, q, home, pos, a, b, step_m)
    return CollisionChecker(model, touch, grown).check(q) if touch else arm.check(q)


def _touching_sweep(
    arm: CollisionChecker,
    q: FloatArray,
    home: Sequence[Part],
    pos: TiltRotatePositioner,
    a: tuple[float, float],
    b: tuple[float, float],
    step_m: float,
) -> list[Part]:
    """``touching(arm, q, swept_bodies(home, pos, a, b, step_m))``, in its order: each clamped body's gaps at every
    sample at once, a sample moved only when it is kept."""
    spheres = arm.shape_spheres(q)
    axes = _samples(home, pos, a, b, step_m)
    X = np.array([pos.move(t, r) for t, r in axes])
    limit = arm.options.min_clearance + _SLACK_M
    keep = np.array([_gaps_moved(spheres, p, X, _grow(arm)) <= limit for p in home]).reshape(len(home), len(X))
    still = [p for p in positioner_parts(pos, *a) if p.name == PEDESTAL]
    out = touching(arm, q, still, spheres)
    for k, (t, r) in enumerate(axes):
        out += [replace(p.transformed(X[k]), name=f"{p.name}@{k}") for i, p in enumerate(home) if keep[i, k]]
        moving = [p for p in positioner_parts(pos, t, r) if p.name != PEDESTAL]
        out += [replace(p, name=f"{p.name}@{k}") for p in touching(arm, q, moving, spheres)]
    return out


def _gaps_moved(spheres: tuple[FloatArray, FloatArray], p: Part, X: FloatArray, grow: float) -> FloatArray:
    """:func:`sphere_gaps`'s bound for body ``p`` moved by each of X (n, 4, 4): (n,) [m]."""
    centres, radii = spheres
    if p.is_box:
        M = X @ p.box.X_AB
        d = centres[None, :, :] - M[:, None, :3, 3]
        local = np.abs(np.einsum("nki,nij->nkj", d, M[:, :3, :3])) - p.box.size / 2.0
        return np.min(np.linalg.norm(np.maximum(local, 0.0), axis=2) - radii[None, :], axis=1) - grow
    c = np.einsum("nij,j->ni", X[:, :3, :3], np.asarray(p.center)) + X[:, :3, 3]
    return (
        np.min(np.linalg.norm(centres[None, :, :] - c[:, None, :], axis=2) - radii[None, :], axis=1) - p.radius - grow
    )


def sphere_gaps(
    arm: CollisionChecker, q: FloatArray, bodies: Sequence[Part], spheres: tuple[FloatArray, FloatArray] | None = None
) -> FloatArray:
    """Per body, a lower bound [m] on its clearance to the arm at q as ``arm``'s options grow it: the least gap
    between an arm shape's bounding sphere (``spheres``: :meth:`CollisionChecker.shape_spheres` at q, computed when
    None) and the body grown by the inflation (a box as itself, any other body as its bounding sphere)."""
    spheres = arm.shape_spheres(q) if spheres is None else spheres
    return np.array([float(_gaps_moved(spheres, p, np.eye(4)[None], _grow(arm))[0]) for p in bodies])


def _grow(arm: CollisionChecker) -> float:
    """The most ``arm``'s collision model grows an obstacle by [m]."""
    return max(arm.options.part_inflation, arm.options.table_inflation)


def touching(
    arm: CollisionChecker, q: FloatArray, bodies: Sequence[Part], spheres: tuple[FloatArray, FloatArray] | None = None
) -> list[Part]:
    """The bodies (in order) whose :func:`sphere_gaps` bound is within the clearance: every body ``arm``'s check at
    q could find in contact; the others are left out of the collision model, whose building is the check's cost."""
    gaps = sphere_gaps(arm, q, bodies, spheres) if bodies else np.zeros(0)
    return [p for p, g in zip(bodies, gaps, strict=True) if g <= arm.options.min_clearance + _SLACK_M]


_SLACK_M = 1e-9  # [m] rounding apart, a body at the clearance's edge is kept


Axes = tuple[float, float]


def clear_route(
    model: RobotModel,
    q: FloatArray,
    home: Sequence[Part],
    pos: TiltRotatePositioner,
    a: Axes,
    b: Axes,
    options: CollisionOptions,
) -> tuple[tuple[Axes, ...], Contact | None]:
    """The positioner's route from ``a`` to ``b`` that sweeps nothing into the arm at ``q``: both axes together,
    else the rotation first and then the tilt, else the tilt first, else laid down at the home tilt, turned
    there and tilted up (a turn made where the part lies, stands or lies flat, as a shop would). Returns the
    route's axes, start excluded, and None; or ((), the straight move's contact) when every route meets the
    arm."""
    flat = pos.home[0]
    routes: tuple[tuple[Axes, ...], ...] = (
        (b,),
        ((a[0], b[1]), b),
        ((b[0], a[1]), b),
        ((flat, a[1]), (flat, b[1]), b),
    )
    first: Contact | None = None
    for route in routes:
        legs = [(s, e) for s, e in itertools.pairwise((a, *route)) if not np.allclose(s, e)]
        hits = (move_hit(model, q, home, pos, s, e, options) for s, e in legs)
        hit = next((h for h in hits if h is not None), None)
        if hit is None:
            return route, None
        first = first or hit
    return (), first
