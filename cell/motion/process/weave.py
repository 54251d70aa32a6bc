"""The path a weld pass's TCP follows: the seam line, shifted to the pass's place in the joint's cross-section,
plus the weave across it (``zigzag``, ``triangle``, ``circle``; docs/planning.md section 4). Values in, arrays
out; no IK here.

Frames: R the robot base; lengths [m], time [s]; the procedure's millimetres converted here."""

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
    return weave_offsets(s, length, weave, speed)[0]


def weave_offsets(s: npt.ArrayLike, length: float, weave: Weave, speed: float) -> tuple[FloatArray, FloatArray]:
    """(lateral along e, lift along b) (n,) each [m] of the weave at distances s (n,) [m] along a seam of
    ``length`` [m] welded at ``speed`` [m/s] (module docstring: the patterns); zeros when it is not active."""
    s = np.asarray(s, dtype=float)
    zero = np.zeros_like(s)
    if not weave.active:
        return zero, zero
    half = 0.5 * weave.width_mm * _MM
    period = 1.0 / weave.frequency_hz
    dl, dr = weave.dwell_s
    t = s / speed
    tau = np.mod(t, period)
    if weave.pattern == "zigzag":
        return _zigzag(s, length, tau, half, period, dl, dr, speed), zero
    t_end = length / speed
    if weave.pattern == "triangle":
        r = 0.5 * (period - dl - dr)  # one crossing [s]
        lat = np.interp(tau, [0.0, 0.5 * r, 0.5 * r + dl, 1.5 * r + dl, 1.5 * r + dl + dr, period],
                        [0.0, half, half, -half, -half, 0.0])  # fmt: skip
        # the line is crossed at every period's start and in the middle of the crossing from +half to -half
        k = np.floor(t_end / period)
        last = k * period + (r + dl if t_end - k * period >= r + dl else 0.0)
        return np.where(t <= last + 1e-12, lat, 0.0), zero
    if weave.pattern == "circle":
        if dl or dr:
            raise ValueError(f"a circle weave has no dwells, got dwell_s {weave.dwell_s}")
        turns = np.floor(t_end / period + 1e-9)  # whole turns only: back on the line at the end
        phi = 2.0 * np.pi * _circle_turns(t / period, turns)
        on = t <= turns * period + 1e-12
        return np.where(on, half * np.sin(phi), 0.0), np.where(on, half * (1.0 - np.cos(phi)), 0.0)
    raise ValueError(f"weave pattern {weave.pattern!r} is not none, zigzag, triangle or circle")


def _ease_out(u: FloatArray) -> FloatArray:
    """0 -> 1 over u in [0, 1] leaving at slope 1 (no curvature) and arriving at rest (slope and curvature 0)."""
    return np.asarray(u + u**3 * (4.0 + u * (-7.0 + 3.0 * u)))


def _circle_turns(n: FloatArray, turns: float) -> FloatArray:
    """The circle's phase [turns] at n [periods] over ``turns`` whole turns: one turn a period, the first turn
    eased in from rest and the last eased out to rest (C2 where the TCP joins the pass line), a single turn a
    smootherstep."""
    if turns <= 1.0:
        return _smootherstep(n)
    first = 1.0 - _ease_out(1.0 - np.clip(n, 0.0, 1.0))
    last = turns - 1.0 + _ease_out(np.clip(n - (turns - 1.0), 0.0, 1.0))
    return np.asarray(np.where(n < 1.0, first, np.where(n > turns - 1.0, last, n)))


def _zigzag(
    s: FloatArray, length: float, tau: FloatArray, half: float, period: float, dl: float, dr: float, speed: float
) -> FloatArray:
    """The zigzag's lateral offset [m] (module docstring) at distances s [m], phase times tau [s]."""
    r = 0.5 * (period - dl - dr)  # one crossing [s]
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
    w_lat, w_lift = weave_offsets(s, length, procedure.weave, pass_speed(procedure, pass_index))
    lat, lift = wp.lateral_mm * _MM + w_lat, wp.lift_mm * _MM + w_lift
    return np.asarray(np.outer(lat, np.asarray(e_R, dtype=float)) + np.outer(lift, np.asarray(b_R, dtype=float)))


def knot_spacing(procedure: WeldProcedure, pass_index: int, spacing: float) -> float:
    """Spacing [m] of the IK knots along a pass: ``spacing``, or a fraction of the weave's wavelength when smaller
    (so the spline through the knots follows the weave): 1/24 for the smooth zigzag and circle, 1/20 for the
    triangle's sharp turns, which the spline rounds over about one knot: finer knots would follow them closer
    (0.1 mm at 1/20 on a 4 mm weave at 1 Hz) but raise the joints' jerk there as the square of the knot count
    (about 70 % of the KR 5 arc's jerk limits at 1/20 on the tiny cell's seam, 85 % at 1/24)."""
    if not procedure.weave.active:
        return spacing
    wavelength = pass_speed(procedure, pass_index) / procedure.weave.frequency_hz
    return min(spacing, wavelength / (20.0 if procedure.weave.pattern == "triangle" else 24.0))


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
