"""The path a weld pass's TCP follows: the seam line, shifted to the pass's place in the joint's cross-section,
plus the weave across it (values in, arrays out; no IK here).

The cross-section of a fillet along d (unit, the weld direction) with faces of outward normals n_a, n_b has two
axes (:func:`cross_section`): the bisector ``b`` (out of the root, between the faces) and ``e`` across it,
perpendicular to d and b, towards face A (``e`` points where face A rises from the root). A pass lies at
``lateral`` along e and ``lift`` along b; a ``zigzag`` weave moves the TCP along e between -width/2 and
+width/2, its phase a function of the distance s along the seam at the travel speed v: a dwell at +width/2 (the
face A side: ``dwell_s[0]``), a crossing, a dwell at -width/2 (``dwell_s[1]``), a crossing back, once per
period 1/f. The crossings follow a quintic smootherstep (zero velocity and acceleration at the dwells: the path
is C2, so the arm's joint accelerations stay bounded), and the width fades in and out over the first and last
wavelength (v/f, at most a quarter of the seam), so the pass starts and ends on its line at rest.

Frames: R the robot base; lengths [m], time [s]; the procedure's millimetres converted here.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types.procedure import Weave, WeldPass, WeldProcedure

_MM = 1e-3


def cross_section(d_R: npt.ArrayLike, n_a_R: npt.ArrayLike, n_b_R: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """(e, b) (3,) each, unit, in R: across the bisector towards face A, and the bisector out of the root."""
    d = np.asarray(d_R, dtype=float)
    d = d / np.linalg.norm(d)
    n_a, n_b = np.asarray(n_a_R, dtype=float), np.asarray(n_b_R, dtype=float)
    b = n_a + n_b
    b = b - (b @ d) * d
    b /= np.linalg.norm(b)
    e = n_b - n_a
    e = e - (e @ d) * d - (e @ b) * b
    return np.asarray(e / np.linalg.norm(e)), np.asarray(b)


def _smootherstep(u: FloatArray) -> FloatArray:
    u = np.clip(u, 0.0, 1.0)
    return np.asarray(u * u * u * (u * (6.0 * u - 15.0) + 10.0))


def pass_speed(procedure: WeldProcedure, pass_index: int) -> float:
    """Travel speed [m/s] of one pass: its own, or the procedure's."""
    p = procedure.passes[pass_index]
    return (p.travel_speed_mm_s or procedure.travel_speed_mm_s) * _MM


def weave_lateral(s: npt.ArrayLike, length: float, weave: Weave, speed: float) -> FloatArray:
    """Lateral offset [m] (along e) of the weave at distances s (n,) [m] along a seam of ``length`` [m] welded at
    ``speed`` [m/s]; zeros when the weave is not active."""
    s = np.asarray(s, dtype=float)
    if not weave.active:
        return np.zeros_like(s)
    half = 0.5 * weave.width_mm * _MM
    period = 1.0 / weave.frequency_hz
    dl, dr = weave.dwell_s
    r = 0.5 * (period - dl - dr)  # one crossing [s]
    tau = np.mod(s / speed, period)
    # +half (dwell left), falling to -half, -half (dwell right), rising to +half
    w = np.where(
        tau < dl,
        half,
        np.where(
            tau < dl + r,
            half - 2.0 * half * _smootherstep((tau - dl) / r),
            np.where(tau < dl + r + dr, -half, -half + 2.0 * half * _smootherstep((tau - dl - r - dr) / r)),
        ),
    )
    fade = min(speed * period, 0.25 * length)
    env = _smootherstep(s / fade) * _smootherstep((length - s) / fade)
    return np.asarray(w * env)


def pass_offsets(
    s: npt.ArrayLike,
    length: float,
    procedure: WeldProcedure,
    pass_index: int,
    e_R: npt.ArrayLike,
    b_R: npt.ArrayLike,
) -> FloatArray:
    """(n, 3) [m] in R: where the TCP of pass ``pass_index`` lies off the seam line at distances s (n,) [m]
    along it: the pass's lateral and lift offsets plus the weave (at the pass's travel speed)."""
    wp: WeldPass = procedure.passes[pass_index]
    lat = wp.lateral_mm * _MM + weave_lateral(s, length, procedure.weave, pass_speed(procedure, pass_index))
    return np.asarray(np.outer(lat, np.asarray(e_R, dtype=float)) + wp.lift_mm * _MM * np.asarray(b_R)[None, :])


def knot_spacing(procedure: WeldProcedure, pass_index: int, spacing: float) -> float:
    """Spacing [m] of the IK knots along a pass: ``spacing``, or 1/24 of the weave's wavelength when smaller
    (so the spline through the knots follows the weave)."""
    if not procedure.weave.active:
        return spacing
    wavelength = pass_speed(procedure, pass_index) / procedure.weave.frequency_hz
    return min(spacing, wavelength / 24.0)


def offset_poses(
    X_line: npt.ArrayLike, length: float, procedure: WeldProcedure, pass_index: int, e_R: FloatArray, b_R: FloatArray
) -> FloatArray:
    """(n, 4, 4): torch poses X_line (n, 4, 4) evenly spaced over the seam's ``length`` [m], moved by the pass's
    offsets and weave (orientation kept)."""
    X = np.array(X_line, dtype=float)
    s = np.linspace(0.0, length, len(X))
    X[:, :3, 3] += pass_offsets(s, length, procedure, pass_index, e_R, b_R)
    return X


def intended_offsets(
    p_R: npt.ArrayLike,
    start_R: npt.ArrayLike,
    d_R: npt.ArrayLike,
    length: float,
    procedure: WeldProcedure,
    pass_index: int,
    e_R: npt.ArrayLike,
    b_R: npt.ArrayLike,
) -> FloatArray:
    """(n, 3) [m]: the offset the plan meant at each executed TCP point p_R (n, 3), from its distance along the
    planned seam (start_R (3,), unit direction d_R (3,), ``length`` [m]): subtract it to compare the TCP with the
    seam itself (the weld quality against the true seam plus the intended weave and pass offset)."""
    p = np.asarray(p_R, dtype=float)
    s = np.clip((p - np.asarray(start_R, dtype=float)) @ np.asarray(d_R, dtype=float), 0.0, length)
    return pass_offsets(s, length, procedure, pass_index, e_R, b_R)
