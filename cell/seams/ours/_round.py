"""A receiving face that is a flat facet of a round body (a gusset standing on a pipe drawn as a 64-gon: its facet
10.7 mm wide, narrower than the gusset and its corner bands), for our locator (frame R, metres): the round's points
beside the seam are taken off the map's cylinder rather than off the facet's plane, so that the plane fit holds the
round's tangent plane along the seam line (docs/curves.md section 7)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types import Cylinder, Part

BoolArray = npt.NDArray[np.bool_]
ALONG_AXIS_COS = math.cos(math.radians(3.0))  # a seam line within this of the round's axis runs along a generator
ON_ROUND_M = 0.001  # a facet is the round's when its plane lies this near the facets' distance from the axis [m]
MAX_ANGLE_RAD = math.radians(40.0)  # the round's points are taken this far round from the seam line at most


@dataclass(frozen=True)
class RoundFace:
    """The round body a facet belongs to (``cylinder``, frame R) and the seam line's distance from its axis
    ``rho0`` [m]; ``n`` (3,), ``d`` the facet's plane (the map's), which the fit moves and tilts."""

    cylinder: Cylinder
    n: FloatArray
    d: float
    rho0: float

    @property
    def bias_m(self) -> float:
        """[m] one sigma of the round's shift at the seam that no fit sees: half the facets' sagitta (the map's
        round runs through the facets' corners; the facets lie up to the sagitta inside it), as the round locator's
        (:func:`cell.seams.curved.locate._bias`)."""
        return 0.5 * self.cylinder.sagitta_m

    def flattening(self, P: FloatArray) -> FloatArray:
        """(k,) [m] how far the map's round at each point (k, 3) lies off the facet's plane along its normal there:
        a point's residual off the plane less this is its height over the round (its radial distance less the seam
        line's), to first order in the fit's small moves and tilts of the plane."""
        return np.asarray(P @ self.n - self.d - (self.cylinder.distance_to_axis(P) - self.rho0))

    def over(self, P: FloatArray, band: float) -> BoolArray:
        """(k,) which points (k, 3) lie over the round beside the seam: along the axis within the body's length
        shrunk by ``band`` [m], and within :data:`MAX_ANGLE_RAD` of the facet's normal round the axis."""
        c = self.cylinder
        s = c.along(P)
        radial = P - c.p_base - np.outer(s, c.axis)
        cos = radial @ self.n / np.maximum(np.linalg.norm(radial, axis=1), 1e-12)
        return np.asarray((s >= band) & (s <= c.length - band) & (cos >= math.cos(MAX_ANGLE_RAD)))


def round_facet(part: Part, face: str, p0: FloatArray, t: FloatArray) -> RoundFace | None:
    """The round ``face`` of ``part`` is a facet of, when the seam line p0 + s t (3,) runs along the round's axis
    on that facet; None for any other face (a box's, a plate's, a facet crossed by the seam at an angle)."""
    c = part.cylinder
    if c is None or c.facets < 3 or abs(float(t @ c.axis)) < ALONG_AXIS_COS:
        return None
    n, d = part.face_plane(face)
    if abs(float(n @ c.axis)) > 1.0 - ALONG_AXIS_COS:
        return None
    apothem = c.radius * math.cos(math.pi / c.facets)
    if abs((d - float(n @ c.p_base)) - apothem) > ON_ROUND_M:
        return None
    rho0 = float(c.distance_to_axis(np.asarray(p0, float)[None, :])[0])
    return RoundFace(c, n, d, rho0)
