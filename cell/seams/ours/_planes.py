"""The planes our locator fits for one seam (frame R, metres): the weld faces, the ends, a plane's support for one
fit, what a seam's pass asks the batched fit for and what it gets back (:mod:`cell.seams.ours.locator`). All are
values: a fit makes new faces and ends, it does not change them."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.seams.ours._points import Points
from cell.seams.sigma import TILT_TOLERANCE_RAD
from cell.types import Part

IntArray = npt.NDArray[np.intp]


@dataclass(frozen=True)
class Face:
    """A weld face being fitted: unit normal n (3,), offset d [m], noise scale [m], offset standard error [m]."""

    n: FloatArray
    d: float
    scale: float
    name: str
    se: float = float("inf")
    count: int = 0  # points of its support
    source: str = "points"  # or "edge of <face>" (an adjacent face of the same part)
    area: float = 0.0  # area of its support region [m^2] (what a head-on view would fill with points)
    note: str = ""  # how well an edge placed it (for the reason)
    tilt_se: float = 0.0  # the offset's spread at the seam's ends from a tilt the points leave within tolerance [m]

    # The constructor, not dataclasses.replace, in the per-pass updates: a third of the cost.
    def moved(self, fit: Fitted, count: int) -> Face:
        """The face moved by its offset fit, supported by ``count`` points."""
        return Face(self.n, self.d + fit.offset, fit.scale, self.name, fit.se, count, self.source, self.area, self.note)

    def tilted(self, tilt: Tilted) -> Face:
        """The face tilted off the map's normal by its tilt step."""
        return Face(
            tilt.n, tilt.d, self.scale, self.name, tilt.se, self.count, self.source, self.area, self.note, tilt.tilt_se
        )

    def with_area(self, area: float) -> Face:
        """The face with the area of its support region [m^2]."""
        return Face(
            self.n, self.d, self.scale, self.name, self.se, self.count, self.source, area, self.note, self.tilt_se
        )


@dataclass(frozen=True)
class End:
    """One end of the seam: a plane across the line (A's side face or the table), or the extent of face A."""

    n: FloatArray
    d: float
    on_table: bool
    s: float = 0.0  # parameter along the line [m]
    se: float = float("inf")
    scale: float = 0.003  # noise of the side face's points [m]
    source: str = "map"
    # The side face lies against another part's face (hidden), that part this thick behind it [m] (0: it does not):
    # the other face's points place it.
    touching: float = 0.0
    gap: float = 0.0  # ... and the drawn gap [m]: d is the other face's plane, the end lies this much short of it
    # A body's flat that ends into a corner radius: the seam ends this far short of the side face's plane [m]
    # (the map's end to that plane; 0 for a box, whose faces meet at sharp edges). docs/bodies.md section 8.
    inset: float = 0.0
    # The statistical standard error of the end's place [m] where the confidence reads another (``se``: an edge's
    # likelihood no better than three point spacings, for the confidence; the likelihood's own for the sigma).
    # None: ``se``.
    sigma: float | None = None
    # The other part whose face a hidden side face lies on (``touching``): only points on that face, inside its
    # outline, place the end (that part's other faces beside A are not it). None: no other part.
    against: Part | None = None
    # What may move the placed end that no fit sees, one standard deviation [m]: an edge's blur and sampling where
    # a face's points stop, a section's size tolerance (an end a drawn width from the other); added to the sigma,
    # not widened with the statistical part.
    bias: float = 0.0
    # How far across face A, away from B, A's own side face here runs [m] (lowest, highest height over the map's
    # line): past it another face ends A (a gusset's snipe stops at the pipe). None: not known (a box, the table).
    span: tuple[float, float] | None = None

    @property
    def spread(self) -> float:
        """The end's statistical standard deviation along the seam [m]: ``sigma``, else ``se``."""
        return self.se if self.sigma is None else self.sigma

    def moved(self, fit: Fitted) -> End:
        """The side face at this end moved by its offset fit."""
        return replace(self, d=self.d + fit.offset, scale=fit.scale, sigma=None, bias=0.0)

    def at(self, s: float, se: float, source: str, sigma: float | None = None, bias: float = 0.0) -> End:
        """This end placed at ``s`` along the line [m], with the standard error the confidence reads [m], where it
        came from, its statistical standard error when another (:attr:`sigma`) and its :attr:`bias` [m]."""
        return replace(self, s=s, se=se, source=source, sigma=sigma, bias=bias)

    @property
    def short_of(self) -> float:
        """How far [m] the seam's end lies short of this end's plane: the drawn gap and the radius's inset."""
        return self.gap + self.inset


END_KEYS = ("start", "end")  # the keys of the selections of A's side faces at the seam's ends


@dataclass(frozen=True, eq=False)
class Selection:
    """A plane's support for one fit: which plane (``key``: ``"a"``, ``"b"`` the weld faces, or one of
    :data:`END_KEYS`), the plane, the residuals r (n,) of all the seam's points from it [m], the indices of its
    support and of the points fitted (an even stride of the support above ``max_fit_points``), and the points its
    fit must keep (a side face keeping fewer is not fitted)."""

    key: str
    plane: Face | End
    r: FloatArray
    sel: IntArray
    fit: IntArray
    need: int = 0
    # A side face's fitted points' heights over faces A and B (2, len(fit)) [m]: the seam's end lies at (0, 0),
    # away from its points, where the part's turn moves the plane by that lever (:func:`at_seam`). None: a weld face.
    across: FloatArray | None = None


@dataclass(frozen=True)
class Fitted:
    """A selection's plane as fitted: the offset it moved by [m], the offset's standard error [m] (the fitted
    stride standing for all the support), its points' noise scale [m] and the fitted points' weights (len(fit),)."""

    offset: float
    se: float
    scale: float
    weights: FloatArray


def at_seam(x: Selection, fit: Fitted) -> float:
    """The standard error [m] of a side face's plane where it meets the seam: the fit holds its offset at its
    points' weighted centre, the seam's end lies at (0, 0) over faces A and B, and a part turned or leaning within
    its angular tolerance (:data:`~cell.seams.sigma.TILT_TOLERANCE_RAD`) moves the plane there by that lever. A
    selection with no heights (:attr:`Selection.across` None): the fit's own standard error."""
    w = np.asarray(fit.weights, dtype=float)
    if x.across is None or len(w) != x.across.shape[1] or w.sum() <= 0.0:
        return fit.se
    centre = x.across @ w / w.sum()  # (2,) [m]
    return float(np.hypot(fit.se, TILT_TOLERANCE_RAD * float(np.linalg.norm(centre))))


@dataclass(frozen=True)
class Tilt:
    """A tilt step a seam's pass asks for after the fit: the weld face of selection ``j`` of the request, the
    other weld face's normal (3,), and p0 (3,) and t (3,) of the line."""

    j: int
    other_n: FloatArray
    p0: FloatArray
    t: FloatArray


@dataclass(frozen=True)
class Tilted:
    """A weld face tilted off the map's normal: its unit normal n (3,), offset d [m] and standard error [m]."""

    n: FloatArray
    d: float
    se: float
    tilt_se: float = 0.0  # the offset's spread at the seam's ends from a tilt the points leave within tolerance [m]


@dataclass(frozen=True)
class FitRequest:
    """What one seam's pass needs fitted: its planes' selections of ``pts``, whether it is the first pass, and
    the tilt steps to take after the fit."""

    selections: list[Selection]
    pts: Points
    first: bool
    tilts: list[Tilt]


@dataclass(frozen=True)
class PassFit:
    """What the batched fit sends back to a seam's pass: each selection's fit (None: not fitted) and each tilt
    step's face (by selection index; None: too few weighted points to tilt)."""

    fits: list[Fitted | None]
    tilted: dict[int, Tilted | None]

    def applied(self, request: FitRequest, face_a: Face, face_b: Face, ends: tuple[End, End]) -> Fitting:
        """The weld faces and the ends after this fit of ``request`` (and its tilt steps)."""
        faces = {"a": face_a, "b": face_b}
        moved = list(ends)
        side_se: dict[int, float] = {}
        for x, fit in zip(request.selections, self.fits, strict=True):
            if fit is None:
                continue
            if x.key in faces:
                faces[x.key] = faces[x.key].moved(fit, len(x.sel))
            else:
                k = END_KEYS.index(x.key)
                moved[k] = moved[k].moved(fit)
                side_se[k] = at_seam(x, fit)
        for j, tilted in self.tilted.items():
            key = request.selections[j].key
            if tilted is not None:
                faces[key] = faces[key].tilted(tilted)
        return Fitting(faces["a"], faces["b"], (moved[0], moved[1]), side_se)


@dataclass(frozen=True)
class Fitting:
    """A seam's planes after a pass's fit: the weld faces, the ends (their side faces moved, not yet placed along
    the line) and the standard errors of the side faces fitted, by end index (0: start, 1: end)."""

    face_a: Face
    face_b: Face
    ends: tuple[End, End]
    sides_se: dict[int, float]


def thin(idx: IntArray, cap: int) -> IntArray:
    """An even stride of the indices ``idx`` leaving at most about ``cap`` of them (deterministic)."""
    return idx[:: len(idx) // cap] if len(idx) > 2 * cap else idx
