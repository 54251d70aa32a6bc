"""A weave along a curve: the procedure's pass offset and weave laid across the seam in the local cross-section at
every knot (across the local bisector towards face A, and along it out of the root), so the weave follows the
curve round (docs/curves-welding.md section 5). Frames: R; metres."""

from __future__ import annotations

import numpy as np

from cell.geometry import FloatArray, readonly
from cell.planning.curves.path import CurvePath
from cell.process.weave import pass_speed, weave_offsets
from cell.types.procedure import WeldProcedure

_MM = 1e-3


def cross_sections(path: CurvePath) -> tuple[FloatArray, FloatArray]:
    """(e, b) (n, 3) each, unit, in R: at every knot of ``path``, across the local bisector towards face A, and
    the local bisector out of the root (:func:`cell.process.weave.cross_section` knot by knot)."""
    d, n_a, n_b = path.t_R, path.n_a_R, path.n_b_R
    b = n_a + n_b
    b = b - np.sum(b * d, axis=1, keepdims=True) * d
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    e = n_b - n_a
    e = e - np.sum(e * d, axis=1, keepdims=True) * d - np.sum(e * b, axis=1, keepdims=True) * b
    return np.asarray(e / np.linalg.norm(e, axis=1, keepdims=True)), np.asarray(b)


def curve_offsets(path: CurvePath, procedure: WeldProcedure, pass_index: int = 0) -> FloatArray:
    """(n, 3) [m] in R: where pass ``pass_index``'s TCP lies off the curve at each knot of ``path``: the pass's
    lateral and lift offsets plus the weave at the pass's travel speed, in the local cross-section."""
    wp = procedure.passes[pass_index]
    lat, lift = weave_offsets(path.s, path.length, procedure.weave, pass_speed(procedure, pass_index))
    e, b = cross_sections(path)
    return np.asarray((wp.lateral_mm * _MM + lat)[:, None] * e + (wp.lift_mm * _MM + lift)[:, None] * b)


def woven(X_RT: FloatArray, path: CurvePath, procedure: WeldProcedure | None, pass_index: int = 0) -> FloatArray:
    """The torch poses X_RT (n, 4, 4) along ``path`` moved by :func:`curve_offsets` (orientation kept); as they
    are without a procedure or when it neither weaves nor offsets the pass."""
    if procedure is None:
        return X_RT
    off = curve_offsets(path, procedure, pass_index)
    if not np.any(off):
        return X_RT
    X = np.array(X_RT, dtype=float)
    X[:, :3, 3] += off
    return readonly(X)
