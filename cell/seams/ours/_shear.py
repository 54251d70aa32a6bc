"""How the ends of a seam on a skewed joint run across face A (frame R, metres): a mitred brace's side faces meet
the seam's line at an angle, so where a point of face A says the end is depends on how far from face B it lies
(:class:`Shear`); and how far an end placed on such a face moves when the line moves across itself
(:func:`across_lever`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.seams.ours._planes import End
from cell.seams.ours._points import Points

# A side face this far off square to the seam (tan of the angle) shears face A's support: below it (a box, whose
# fitted faces tilt a little off the map's) the window along the seam stays square.
_SHEAR_MIN = float(np.tan(np.radians(1.0)))


@dataclass(frozen=True)
class Shear:
    """How A's side faces at the seam's ends run across face A (a mitred brace's, at an angle to the seam).

    w : (3,) the unit direction in face A across the seam, away from face B; h0 : where along w A's edge on its end
        face lies [m] (the drawn gap over the angle between the end face and w; 0 without one); c : a side face
        meets that edge at ``s(h0) - c (h - h0)`` along the seam at a height h along w, so that ``s + c (h - h0)``
        of a point of face A is where the side line through it meets A's edge at the end face: the end's place as
        the truth has it (the edge projected on the seam). 0 for ends square to the seam (a box: all as before).
        ``ends``: each end's own slope (a gusset's sniped corner at 45 deg at one end, its square toe or its
        hypotenuse at the other), c for both when they share it.
    """

    w: FloatArray
    c: float
    h0: float
    ends: tuple[float, float] | None = None
    spans: tuple[tuple[float, float] | None, tuple[float, float] | None] = (None, None)  # each end's :attr:`End.span`

    def slope(self, k: int | None) -> float:
        """End k's slope (0: the start, 1: the end); None: the mean, :attr:`c`."""
        return self.c if k is None or self.ends is None else self.ends[k]

    def s(self, pts: Points, p0: FloatArray, t: FloatArray, k: int | None = None) -> FloatArray:
        """The points' parameters along the seam p0 + s t, each carried along its side line (end k's; None: the
        mean slope) to A's end edge."""
        s = pts.along(t) - float(p0 @ t)
        c = self.slope(k)
        if not c:
            return s
        return s + c * (pts.along(self.w) - float(p0 @ self.w) - self.h0)

    def beside(self, pts: Points, p0: FloatArray, k: int, margin: float) -> npt.NDArray[np.bool_]:
        """(n,) which points lie across face A within end k's side face's :attr:`End.span` (grown by ``margin``
        [m]): where that face is what ends A (past it, another face does); all when the ends share a slope."""
        span = self.spans[k]
        if self.ends is None or span is None:
            return np.ones(len(pts.cam), bool)
        h = pts.along(self.w) - float(p0 @ self.w)
        return np.asarray((h >= span[0] - margin) & (h <= span[1] + margin))


def end_slopes(ends: tuple[End, End], n_a: FloatArray, n_b: FloatArray, t: FloatArray) -> tuple[float, float]:
    """Each end plane's slope across face A (see :class:`Shear`): how far along the seam [m] its end moves per metre
    that A's edge on its end face lies further from face B than drawn (an as-built gap); 0 for a plane square to the
    seam or one that does not cross it."""
    w = np.cross(n_a, t)
    w = w / max(float(np.linalg.norm(w)), 1e-12)
    if float(w @ n_b) < 0.0:
        w = -w
    out = [float(e.n @ w) / float(e.n @ t) if abs(float(e.n @ t)) > 0.2 else 0.0 for e in ends]
    return out[0], out[1]


def across_lever(end: End, t: FloatArray) -> float:
    """How far along the seam [m] an end placed on a side face moves per metre the line moves across itself, at
    most (the worst direction across): the tangent of the face's normal's angle to the line; 0 for an end no plane
    places, or a plane along the line."""
    if end.source not in ("side face", "table"):
        return 0.0
    c = abs(float(end.n @ t))
    return float(np.sqrt(max(1.0 - c * c, 0.0)) / c) if c > 0.2 else 0.0


def end_shear(
    ends: tuple[End, End],
    n_a: FloatArray,
    n_b: FloatArray,
    t: FloatArray,
    p0: FloatArray,
    end_face: tuple[FloatArray, float],
) -> Shear:
    """The :class:`Shear` of the ends' planes (the table or another part's face included: what A's side lies on;
    their mean slope), face A (normal ``n_a``) meeting face B (``n_b``) on the line p0 + s t, A's end face the
    plane ``end_face`` (n, d)."""
    w = np.cross(n_a, t)
    w = w / max(float(np.linalg.norm(w)), 1e-12)
    if float(w @ n_b) < 0.0:
        w = -w
    each = [float(e.n @ w) / float(e.n @ t) if abs(float(e.n @ t)) > 0.2 else None for e in ends]
    slopes = [x for x in each if x is not None]
    c = float(np.mean(slopes)) if slopes else 0.0
    own = (c if each[0] is None else each[0], c if each[1] is None else each[1])
    if max(abs(own[0]), abs(own[1])) < _SHEAR_MIN:
        return Shear(w, 0.0, 0.0)
    n_e, d_e = end_face
    h0 = (d_e - float(n_e @ p0)) / float(n_e @ w) if abs(float(n_e @ w)) > 0.3 else 0.0
    if abs(own[0] - own[1]) < _SHEAR_MIN:
        return Shear(w, c, max(h0, 0.0))
    return Shear(w, c, max(h0, 0.0), own, (ends[0].span, ends[1].span))
