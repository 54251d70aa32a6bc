"""A located curve made ready to weld: resampled evenly along its length from a chosen start and direction (a
closed curve run on past its start by the overlap), and the torch poses along it, each on the local bisector of
the two faces with the travel angle along the local tangent (docs/curves-welding.md section 1).

Frames: everything in the robot base frame R [m]; angles [rad]."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from cell.errors import PlanError
from cell.geometry import FloatArray, readonly
from cell.process.torch import WeldProcess
from cell.types.curve_estimate import CurveEstimate


@dataclass(frozen=True)
class CurvePath:
    """A curve to weld, sampled evenly along its length from its weld start: points p_R (n, 3), unit tangents
    t_R (n, 3) in the weld direction, the faces' outward unit normals n_a_R, n_b_R (n, 3) (the abutting part's,
    the receiving part's), s (n,) the length welded so far [m]; closed: a full loop, whose last ``overlap`` [m]
    runs again over the start's bead (0 for an open curve); start: where on the located curve the weld starts (the
    length from its first sample [m]); reversed: welded against the located curve's order."""

    p_R: FloatArray
    t_R: FloatArray
    n_a_R: FloatArray
    n_b_R: FloatArray
    s: FloatArray
    closed: bool
    overlap: float
    start: float
    reversed: bool

    def __post_init__(self) -> None:
        for name in ("p_R", "t_R", "n_a_R", "n_b_R", "s"):
            object.__setattr__(self, name, readonly(np.asarray(getattr(self, name), dtype=float)))

    @property
    def length(self) -> float:
        """The length welded [m] (a closed curve's loop plus its overlap)."""
        return float(self.s[-1])


def _loop(est: CurveEstimate) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """(points, abutting normals, receiving normals, arc length at each) of the located curve, a closed one with
    its first sample repeated at the end."""
    p, na, nb = np.asarray(est.p_RS), np.asarray(est.n_abutting_R), np.asarray(est.n_receiving_R)
    if est.closed:
        p, na, nb = np.vstack([p, p[:1]]), np.vstack([na, na[:1]]), np.vstack([nb, nb[:1]])
    step = np.linalg.norm(np.diff(p, axis=0), axis=1)
    keep = np.concatenate([[True], step > 1e-9])  # coincident samples would stall the spline
    s = np.concatenate([[0.0], np.cumsum(step)])[keep]
    return p[keep], na[keep], nb[keep], s


def curve_path(
    est: CurveEstimate, spacing: float, *, start: float = 0.0, reverse: bool = False, overlap: float = 0.0
) -> CurvePath:
    """The located curve ``est`` resampled at most ``spacing`` [m] apart, evenly, ready to weld.

    start [m] : where a closed curve's weld starts, as a length from its first sample (taken modulo its length;
        an open curve always starts at one of its ends). reverse : weld against the samples' order (an open curve
        then starts at its last sample). overlap [m] : how far a closed curve is welded on past its start.
    Positions follow a C2 cubic spline through the samples in arc length (periodic for a closed curve), normals
    are interpolated linearly and made unit. PlanError for a curve shorter than 1 mm.
    """
    if not spacing > 0.0:
        raise ValueError(f"curve_path: spacing must be positive, got {spacing}")
    p, na, nb, s_k = _loop(est)
    total = float(s_k[-1]) if len(s_k) > 1 else 0.0
    if total < 1e-3:
        raise PlanError(f"curved seam {est.id}: {total * 1000:.2f} mm long, needs at least 1 mm to weld")
    spline = CubicSpline(s_k, p, axis=0, bc_type="periodic" if est.closed else "not-a-knot")
    weld = total + (overlap if est.closed else 0.0)
    n = max(2, math.ceil(weld / spacing - 1e-9) + 1)
    u = np.linspace(0.0, weld, n)  # the length welded
    sign = -1.0 if reverse else 1.0
    s0 = (start % total) if est.closed else (total if reverse else 0.0)
    at = s0 + sign * u
    if est.closed:
        at = np.mod(at, total)
    pts = spline(at)
    tan = sign * spline(at, 1)
    tan /= np.linalg.norm(tan, axis=1, keepdims=True)

    def normals(nk: FloatArray) -> FloatArray:
        v = np.column_stack([np.interp(at, s_k, nk[:, j]) for j in range(3)])
        v -= np.sum(v * tan, axis=1, keepdims=True) * tan  # a face holds the curve: its normal is across it
        return np.asarray(v / np.linalg.norm(v, axis=1, keepdims=True))

    return CurvePath(pts, tan, normals(na), normals(nb), u, est.closed, weld - total, s0, reverse)


def _unit_rows(v: FloatArray) -> FloatArray:
    return np.asarray(v / np.linalg.norm(v, axis=1, keepdims=True))


def _along(v: FloatArray, d: FloatArray) -> FloatArray:
    return np.asarray(np.sum(v * d, axis=1, keepdims=True))


def torch_rotations(
    t_R: FloatArray, n_a_R: FloatArray, n_b_R: FloatArray, work_angle: float | FloatArray,
    travel_angle: float | FloatArray,
) -> FloatArray:  # fmt: skip
    """R_RT (n, 3, 3): :func:`cell.process.torch.torch_rotation` (spin 0) at n samples at once, for tangents t_R
    and the faces' outward normals n_a_R, n_b_R (n, 3) each: the work angle about the local bisector of the local
    dihedral, the travel angle along the local tangent (each one value or one per sample, (n,))."""
    d = _unit_rows(np.asarray(t_R, dtype=float))
    na = _unit_rows(np.asarray(n_a_R, dtype=float))
    nb_raw = _unit_rows(np.asarray(n_b_R, dtype=float))
    nb = _unit_rows(nb_raw - _along(nb_raw, d) * d)
    na_p = na - _along(na, d) * d
    t_b = _unit_rows(na_p - _along(na_p, nb) * nb)
    ta = nb - _along(nb, na) * na
    t_a = _unit_rows(ta - _along(ta, d) * d)
    angle = np.arctan2(_along(t_a, nb), _along(t_a, t_b))
    angle = np.where(np.abs(angle - 0.5 * math.pi) < 1e-9, 0.5 * math.pi, angle)
    work = np.reshape(np.asarray(work_angle, dtype=float), (-1, 1))  # one value, or one per sample
    travel = np.reshape(np.asarray(travel_angle, dtype=float), (-1, 1))
    w = work + 0.5 * angle - 0.25 * math.pi
    u = np.cos(w) * t_b + np.sin(w) * nb
    z = -np.cos(travel) * u + np.sin(travel) * d
    x = _unit_rows(d - _along(d, z) * z)
    return np.stack([x, np.cross(z, x), z], axis=2)


def curve_poses(
    path: CurvePath,
    process: WeldProcess,
    *,
    spin: float | FloatArray = 0.0,
    work_offset: float | FloatArray = 0.0,
    travel_offset: float | FloatArray = 0.0,
    flange: tuple[FloatArray, FloatArray] | None = None,
) -> FloatArray:
    """X_RT (n, 4, 4), read-only: the torch poses along ``path``, at each sample the orientation
    :func:`cell.process.torch.torch_rotation` gives (:func:`torch_rotations`) for the local tangent and the two
    faces' local normals (the work angle on the local bisector, the travel angle along the tangent, push or drag
    as the process says) and a spin about the torch axis; the wire tip backed off the curve along the torch axis
    by ``process.standoff``.

    flange : (z_T, z_R), the flange's axis (A6's) in the torch frame and the way it should point in R, both (3,)
        unit: at each sample the torch is spun about its axis to bring the flange's axis nearest z_R (the wrist
        held as it is at home while the torch goes round the curve, so A4 and A5 stay put and A6 alone turns with
        the curve), then by ``spin`` [rad] more. None, or a flange axis along the torch's: ``spin`` alone.
    ``spin``, ``work_offset``, ``travel_offset``: one value, or one per sample (n,) (the torch turned and tilted
    along the curve). The orientation is continuous wherever the curve's tangent and normals are (spins unwrapped)."""
    work = process.work_angle + work_offset
    travel = process.travel_angle + travel_offset
    n = len(path.s)
    base = torch_rotations(path.t_R, path.n_a_R, path.n_b_R, work, travel)
    spins = np.broadcast_to(np.asarray(spin, dtype=float), (n,)).copy()
    if flange is not None and float(np.hypot(flange[0][0], flange[0][1])) > 0.2:
        z_T, z_R = flange
        w = np.einsum("nji,j->ni", base, z_R)  # z_R in each unspun torch frame
        spins = spin + np.unwrap(np.arctan2(w[:, 1], w[:, 0]) - math.atan2(z_T[1], z_T[0]))
    c, s_ = np.cos(spins), np.sin(spins)
    out = np.zeros((n, 4, 4))
    out[:, :3, 0] = c[:, None] * base[:, :, 0] + s_[:, None] * base[:, :, 1]
    out[:, :3, 1] = -s_[:, None] * base[:, :, 0] + c[:, None] * base[:, :, 1]
    out[:, :3, 2] = base[:, :, 2]
    out[:, :3, 3] = path.p_R - process.standoff * base[:, :, 2]
    out[:, 3, 3] = 1.0
    return readonly(out)


def start_order(est: CurveEstimate, p_base_R: FloatArray, count: int) -> list[float]:
    """Where to try starting a closed curve's weld, as lengths from its first sample [m]: ``count`` points
    evenly round it, the one nearest the robot base ``p_base_R`` (3,) first (the torch there reaches in
    comfortably, and the loop's wrist travel is shared either side of it), then alternately either side of it."""
    p, _, _, s = _loop(est)
    total = float(s[-1])
    k = int(np.argmin(np.linalg.norm(p[:-1, :2] - np.asarray(p_base_R)[:2], axis=1)))
    first = float(s[k])
    steps = [0]
    for i in range(1, count):
        steps.append((i + 1) // 2 * (1 if i % 2 else -1))
    return [(first + j * total / count) % total for j in steps]
