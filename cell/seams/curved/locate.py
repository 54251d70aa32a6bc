"""Our locator for curved seams: the points near the drawn curve's two surfaces taken from the dense cloud, each
surface fitted locally (:mod:`cell.seams.curved.fit`), the two fitted surfaces intersected from the drawn curve's
samples, with each sample's sigma across the seam propagated from the fits (docs/curves.md). Frame R, metres."""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from cell.geometry import FloatArray
from cell.seams._index import dense_index
from cell.seams.curved.cut import outside_parts
from cell.seams.curved.fit import SurfaceFit, fit_surface
from cell.seams.curved.surfaces import CylinderModel, PlaneModel, SurfaceModel, crossing_covariance, intersect
from cell.seams.curved.surfaces import param_jacobian as dtheta
from cell.types import CurvedSeam, Part, Reason, SeamScene, SeamStatus, Surface, WeldMap
from cell.types.curve_estimate import CurveEstimate
from cell.weldmap.curved_joints import holding_face

CURVE_METHODS = ("ours",)  # the locators that locate curved seams; the others answer NOT_SUPPORTED
STEP_M = 0.001  # the located curve's samples are about this far apart [m]
# A surface's points are taken within a band of the map's surface [m]: three of their depth noise's scale (each
# point's scatter about its neighbours across the surface: a camera's pose error, which moves its neighbours with
# it, is not in it) beyond the aligned map's own offset, between these bounds. A band cut narrower than the scatter
# shifts the points' mean towards the map (round-brace's plate, 1.5 mm of noise, 0.6 mm off the map: 0.14 mm); past
# 4.5 mm the noisiest cameras' points (2-2.5 mm on random cells) add more scatter than they take bias away
# (docs/curves.md section 8).
BAND_M = 0.003
MAX_BAND_M = 0.0045
BAND_SCALES = 3.0
MAP_OFFSET_M = 0.001
CLEARANCE_M = 0.002  # points this close to the other surface are left out (the corner's blur, a tack) [m]
REACH_M = 0.025  # how far from the other surface a plane's points are taken [m]: the fit is local
ROUND_REACH_M = 0.120  # and a tube's [m]: its axis's direction wants a longer lever
RADIUS_SHARE = 0.005  # a tube's outer radius as made, one sigma: EN 10219's +-1 % of the diameter as two sigma
SHARE = 0.25  # the dense cloud's layer looked at (one of its index's shares)
MAX_POINTS = 1500  # per surface: more are thinned evenly (the fit's standard error shrinks little past it)
MIN_POINTS = 60  # fewer points on a surface: the data does not hold it
MAX_MOVE_M = 0.010  # a located curve further than this from the drawn one is not the seam [m]
MAX_SIGMA_M = 0.002  # a located curve with a sigma larger than this somewhere is not reported [m]
FACE_EDGE_M = 0.002  # a plane's points this close to its face's edges are left out [m]
NORMAL_ANGLE_RAD = math.radians(45.0)  # a point whose normal is further than this from its surface's is not on it
NORMAL_NEIGHBOURS = 8  # a point and its nearest neighbours make its patch
OTHER_PART_M = 0.002  # points this close to (or inside) a part of the map other than the two are not theirs [m]

# How much wider the spread of the located curve is than its propagated standard error, and how far either surface
# may lie from where its points put it, for what no point count shrinks (a camera's depth bias, a tessellated round's
# facets): checked on benchmarks/bench_curves.py (docs/curves.md sections 2 and 3).
SE_INFLATION = 1.2
SURFACE_BIAS_M = 0.00012


def reference_surface(part: Part, kind: Surface, p_R: FloatArray) -> SurfaceModel | str:
    """The reference surface of ``part`` of ``kind`` holding the curve's samples p_R (n, 3), or why there is none."""
    centre = p_R.mean(axis=0)
    if kind is Surface.CYLINDER:
        if part.cylinder is None:
            return f"part {part.name} is not recognised as a round body"
        return CylinderModel.about(part.cylinder, centre)
    face = holding_face(part, p_R)
    if face is None:
        return f"no face of part {part.name} holds the drawn curve"
    n, d = part.face_plane(face)
    return PlaneModel(centre - (centre @ n - d) * n, n)


def _candidates(
    scene: SeamScene, p: FloatArray, models: Sequence[SurfaceModel]
) -> tuple[FloatArray, npt.NDArray[np.intp]]:
    """(m, 3) the dense cloud's points of the layer :data:`SHARE` about the curve through the points p (n, 3) (a
    tube along its round part), and their cameras (m,)."""
    cyl = next(m for m in models if isinstance(m, CylinderModel))
    along = (p - cyl.c0) @ cyl.u0
    a, b = cyl.c0 + (along.min() - ROUND_REACH_M) * cyl.u0, cyl.c0 + (along.max() + ROUND_REACH_M) * cyl.u0
    pts, cams = dense_index(scene).tube(a, b, cyl.r0 + REACH_M + MAX_BAND_M, 0.0, SHARE)
    return np.ascontiguousarray(pts.T), cams


def _thin(mask: npt.NDArray[np.bool_]) -> npt.NDArray[np.intp]:
    """The indices of ``mask``'s True entries, evenly thinned to :data:`MAX_POINTS` at most."""
    idx = np.flatnonzero(mask)
    return idx if len(idx) <= MAX_POINTS else idx[:: math.ceil(len(idx) / MAX_POINTS)]


def _reach(model: SurfaceModel) -> float:
    """How far from the other surface this one's points are taken [m]: a tube's further (its axis is straight)."""
    return ROUND_REACH_M if isinstance(model, CylinderModel) else REACH_M


def _prior(model: SurfaceModel) -> FloatArray | None:
    """A tube's radius is known to its tolerance (:data:`RADIUS_SHARE`); its axis and a plane's pose are left to the
    points."""
    if not isinstance(model, CylinderModel):
        return None
    return np.array([np.inf, np.inf, np.inf, np.inf, RADIUS_SHARE * model.r0])


def _on_face(part: Part, model: SurfaceModel, q: FloatArray) -> npt.NDArray[np.bool_]:
    """(k,) which points q (k, 3) of a plane surface lie on its part's face away from the face's edges by
    :data:`FACE_EDGE_M` (another face of the part meets it there: a rail's side, a post's corner); all of a
    cylinder's."""
    if not isinstance(model, PlaneModel) or not len(q):
        return np.ones(len(q), bool)
    depth = model.value(q, np.zeros(model.size)) + FACE_EDGE_M + 0.0005
    return np.asarray(part.contains(q - depth[:, None] * model.n0, -FACE_EDGE_M))


def _facing(
    m1: SurfaceModel, m2: SurfaceModel, q1: FloatArray, q2: FloatArray
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_], FloatArray]:
    """Which points of q1, q2 (k, 3) of each surface have a neighbourhood (among both) lies flat across their surface's
    normal g: the spread along g is at most sin^2(:data:`NORMAL_ANGLE_RAD`) / 2 of the whole (a flat patch tilted
    by that angle from the surface; a side face, an edge or a stray point beside the surface is not on it); and each
    point's neighbourhood's standard deviation along g [m] (the points of q1, then q2)."""
    both = np.vstack([q1, q2])
    if len(both) <= NORMAL_NEIGHBOURS:
        return np.ones(len(q1), bool), np.ones(len(q2), bool), np.zeros(len(both))
    tree = cKDTree(both)
    _, idx = tree.query(both, k=NORMAL_NEIGHBOURS)
    nb = both[idx] - both[idx].mean(axis=1, keepdims=True)  # (n, k, 3)
    g = np.vstack([m1.implicit(np.zeros(m1.size))(q1)[1], m2.implicit(np.zeros(m2.size))(q2)[1]])
    along = np.einsum("nkd,nd->nk", nb, g)
    ratio = (along**2).sum(axis=1) / np.maximum((nb**2).sum(axis=(1, 2)), 1e-30)
    flat = ratio <= 0.5 * math.sin(NORMAL_ANGLE_RAD) ** 2
    spread = np.sqrt((along**2).sum(axis=1) / (NORMAL_NEIGHBOURS - 1))
    return flat[: len(q1)], flat[len(q1) :], spread


def _from_outside(
    scene: SeamScene, model: SurfaceModel, q: FloatArray, cams: npt.NDArray[np.intp]
) -> npt.NDArray[np.bool_]:
    """(k,) which points q (k, 3) of a surface their camera saw from its outward side (a hollow tube's bore, seen
    down its open end, lies within the band of its outer round when the map sits a little off); every point whose
    camera's centre is not known."""
    keep = np.ones(len(q), bool)
    names = scene.dense.cameras
    g = model.implicit(np.zeros(model.size))(q)[1] if len(q) else np.zeros((0, 3))
    for c in np.unique(cams):
        eye = scene.eyes_R.get(names[c]) if 0 <= c < len(names) else None
        if eye is None:
            continue
        mine = cams == c
        keep[mine] = np.einsum("ij,ij->i", q[mine] - np.asarray(eye), g[mine]) < 0.0
    return keep


def _bias(fit: SurfaceFit, bias_share: float | None = None) -> float:
    """[m] one sigma of a shift of the fitted surface along its normal that its covariance does not hold: the
    cameras' common bias (:data:`SURFACE_BIAS_M`, or ``bias_share`` of the fit's noise scale), what the model leaves
    unexplained over patches of its points (``lack_m``), the cameras' disagreement (``cameras_m``: their pose
    errors) and, for a round drawn with flat facets, half the facets' sagitta (a circle fitted to a polygon)."""
    sag = 0.0
    if isinstance(fit.model, CylinderModel) and fit.model.facets > 0:
        sag = fit.model.r0 * (1.0 - math.cos(math.pi / fit.model.facets))
    common = SURFACE_BIAS_M if bias_share is None else bias_share * fit.scale_m
    return math.hypot(common, fit.lack_m, fit.cameras_m, 0.5 * sag)


def _not_found(seam: CurvedSeam, why: str, code: Reason = Reason.NO_SUPPORT) -> CurveEstimate:
    """NOT_FOUND with ``why``; NOT_SUPPORTED (never searched) when ``code`` says the seam's geometry is not one
    this locator handles."""
    status = SeamStatus.NOT_SUPPORTED if code is Reason.NOT_SUPPORTED else SeamStatus.NOT_FOUND
    return CurveEstimate(seam.id, status, f"curved seam {seam.id}: {why}", code=code)


def _select(
    scene: SeamScene,
    p: FloatArray,
    cams: npt.NDArray[np.intp],
    models: tuple[SurfaceModel, SurfaceModel],
    parts: tuple[Part, Part],
    own: set[str],
) -> tuple[tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]], tuple[int, int]]:
    """The indices of the points p (k, 3) on each surface (docs/curves.md section 1, step 2), and how many lay in
    each's widest band before the thinning: each band :data:`BAND_SCALES` of the surface's depth noise (the median
    of its points' neighbourhoods' spread across it) beyond :data:`MAP_OFFSET_M`, within [BAND_M, MAX_BAND_M]."""
    m1, m2 = models
    f1, f2 = m1.value(p, np.zeros(m1.size)), m2.value(p, np.zeros(m2.size))
    on1 = (np.abs(f1) < MAX_BAND_M) & (f2 > CLEARANCE_M) & (f2 < _reach(m1))
    on2 = (np.abs(f2) < MAX_BAND_M) & (f1 > CLEARANCE_M) & (f1 < _reach(m2))
    near = np.flatnonzero(on1 | on2)
    theirs = outside_parts(scene.weldmap, p[near], own, OTHER_PART_M)
    on1[near[~theirs]] = on2[near[~theirs]] = False
    i1, i2 = _thin(on1), _thin(on2)
    i1, i2 = i1[_on_face(parts[0], m1, p[i1])], i2[_on_face(parts[1], m2, p[i2])]
    f1s, f2s, spread = _facing(m1, m2, p[i1], p[i2])
    out = []
    for idx, flat, s, f in ((i1, f1s, spread[: len(i1)], f1), (i2, f2s, spread[len(i1) :], f2)):
        noise = float(np.median(s[flat])) if flat.any() else 0.0
        band = min(MAX_BAND_M, max(BAND_M, BAND_SCALES * noise + MAP_OFFSET_M))
        out.append(idx[flat & (np.abs(f[idx]) < band)])
    i1, i2 = out
    i1, i2 = i1[_from_outside(scene, m1, p[i1], cams[i1])], i2[_from_outside(scene, m2, p[i2], cams[i2])]
    return (i1, i2), (int(on1.sum()), int(on2.sum()))


def locate_curve(
    scene: SeamScene, seam: CurvedSeam, *, max_sigma_m: float = MAX_SIGMA_M, bias_share: float | None = None
) -> CurveEstimate:
    """One curved seam of ``scene``'s aligned map located in its dense cloud (time left to the caller); NOT_FOUND
    (``low_confidence``) when a sample's sigma exceeds ``max_sigma_m`` [m] (inf: never: close-ups that see part of
    the curve leave the rest to the fixed cameras). ``bias_share``: each surface's shift that no fit sees as this
    share of its points' noise scale (None: :data:`SURFACE_BIAS_M`, the fixed cameras')."""
    joint = seam.joint
    if joint is None:
        return _not_found(seam, f"no two parts hold it ({seam.note})", Reason.NOT_SUPPORTED)
    wm = scene.weldmap
    drawn = seam.sample(STEP_M)
    parts = (wm.part(joint.abutting), wm.part(joint.receiving))
    kinds = (joint.abutting_surface, joint.receiving_surface)
    models = [reference_surface(part, kind, drawn) for part, kind in zip(parts, kinds, strict=True)]
    for m in models:
        if isinstance(m, str):
            return _not_found(seam, m, Reason.NOT_SUPPORTED)
    m1, m2 = models[0], models[1]
    assert not isinstance(m1, str) and not isinstance(m2, str)
    p, cams = _candidates(scene, drawn, (m1, m2))
    own = {joint.abutting, joint.receiving}
    (i1, i2), counts = _select(scene, p, cams, (m1, m2), parts, own)
    fits = (
        fit_surface(m1, p[i1], MIN_POINTS, _prior(m1), cams[i1]),
        fit_surface(m2, p[i2], MIN_POINTS, _prior(m2), cams[i2]),
    )
    for part, kind, fit, count in zip(parts, kinds, fits, counts, strict=True):
        if not fit.ok:
            return _not_found(seam, f"the {kind} of {part.name} is not held by the cloud ({count} points near it)")
    return _curve(seam, drawn, fits, wm, own, max_sigma_m, bias_share)


def _curve(
    seam: CurvedSeam,
    drawn: FloatArray,
    fits: tuple[SurfaceFit, SurfaceFit],
    wm: WeldMap,
    own: set[str],
    max_sigma_m: float,
    bias_share: float | None,
) -> CurveEstimate:
    """The fitted surfaces intersected from the drawn samples, cut where another part stands, with sigmas."""
    a, b = fits
    s1, s2 = a.model.implicit(a.theta), b.model.implicit(b.theta)
    p = intersect(drawn, s1, s2)
    (v1, g1), (v2, g2) = s1(p), s2(p)
    if not (np.abs(v1).max() < 1e-6 and np.abs(v2).max() < 1e-6):
        return _not_found(seam, "its fitted surfaces do not meet near the drawn curve")
    moved = float(np.linalg.norm(p - drawn, axis=1).max())
    if moved > MAX_MOVE_M:
        return _not_found(seam, f"its fitted surfaces meet {moved * 1000:.1f} mm from the drawn curve")
    k2 = SE_INFLATION**2
    da, db = dtheta(a.model, p, a.theta), dtheta(b.model, p, b.theta)
    cov = crossing_covariance(p, g1, g2, da, k2 * a.cov, db, k2 * b.cov, (_bias(a, bias_share), _bias(b, bias_share)))
    sigma = np.sqrt(np.trace(cov, axis1=1, axis2=2))
    closed = bool(getattr(seam.curve, "closed", False))
    keep = outside_parts(wm, p, own, OTHER_PART_M)
    end_sigma = (0.0, 0.0)
    if not closed:
        from cell.seams.sigma import drawn_end_sigma

        end_sigma = (drawn_end_sigma(), drawn_end_sigma())
    out = CurveEstimate(
        seam.id,
        SeamStatus.FOUND,
        p_RS=p,
        n_abutting_R=g1 / np.linalg.norm(g1, axis=1, keepdims=True),
        n_receiving_R=g2 / np.linalg.norm(g2, axis=1, keepdims=True),
        closed=closed,
        sigma_m=sigma,
        end_sigma_m=end_sigma,
        confidence=curve_confidence(sigma),
    )
    if not keep.all():
        from cell.seams.curved.cut import longest_run

        out = longest_run(out, keep)
    if out.status is SeamStatus.FOUND and out.sigma_max_m > max_sigma_m:
        why = f"its surfaces are held too weakly (sigma up to {out.sigma_max_m * 1000:.1f} mm)"
        return _not_found(seam, why, Reason.LOW_CONFIDENCE)
    return out


def curve_confidence(sigma_m: FloatArray) -> float:
    """A located curve's confidence from its samples' sigmas (n,) [m]: 1 - the largest over :data:`MAX_SIGMA_M`."""
    return float(np.clip(1.0 - float(np.max(sigma_m)) / MAX_SIGMA_M, 0.0, 1.0))


def _not_supported(seam: CurvedSeam, method: str) -> CurveEstimate:
    why = f"curved seam {seam.id}: the {method} locator finds straight seams only (curved seams: ours)"
    return CurveEstimate(seam.id, SeamStatus.NOT_SUPPORTED, why, code=Reason.NOT_SUPPORTED)


def locate_curves(method: str, scene: SeamScene) -> tuple[CurveEstimate, ...]:
    """Every curved seam of ``scene``'s map by ``method``, in the map's order, each with its time (the dense
    cloud's index made before the clock starts): ours locates them, the others answer NOT_SUPPORTED."""
    if method not in CURVE_METHODS:
        return tuple(_not_supported(seam, method) for seam in scene.weldmap.curved)
    if scene.weldmap.curved:
        dense_index(scene)  # perception's work (the ordered cloud), as for the straight seams
    out = []
    for seam in scene.weldmap.curved:
        t = time.perf_counter()
        est = locate_curve(scene, seam)
        out.append(replace(est, time_s=time.perf_counter() - t))
    return tuple(out)
