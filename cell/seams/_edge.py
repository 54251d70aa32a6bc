"""Placing a face no camera sees from the edge where an adjacent face of the same part ends (our locator's step 4):
the extent of that face's points across the edge, per camera by a blurred-step likelihood, with a standard error
from the edge's own data. Everything in the robot frame R, metres."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.seams._extent import EDGE_BLURS, EdgeFit, edge_fit
from cell.seams._lines import extent_behind, line_box_span, plane_intersection
from cell.seams._robust import histogram_mode, robust_offset
from cell.types import BOX_FACES, Box, Part, Polyhedron

BoolArray = npt.NDArray[np.bool_]
IntArray = npt.NDArray[np.intp]
_Z = np.array([0.0, 0.0, 1.0])
_ROUND_COS = np.cos(np.radians(30.0))  # an adjacent face this near the face's own plane is a corner radius's facet
ROUND_BLUR_M = 1e-3  # a rounded edge seen blurred over this much is a silhouette, not the face's plane [m]

# The points of the cloud within ``radius`` [m] of the segment a-b (3,): (n, 3) [m], camera (n,), whether each
# may support a plane (above the table, away from the map's other parts), and whether its camera lies in front of
# the face being placed (all True where the cameras' centres are not known).
Points = Callable[[FloatArray, FloatArray, float], tuple[FloatArray, IntArray, BoolArray, BoolArray]]


class EdgeOptions(Protocol):
    """What edge placement reads of the locator's options (:class:`cell.seams.ours.OursOptions`); lengths [m]."""

    @property
    def map_tolerance_m(self) -> float: ...  # how far the as-built faces may lie from the aligned map
    @property
    def sensor_sigma_m(self) -> float: ...  # depth noise assumed before it is measured
    @property
    def edge_band_m(self) -> float: ...  # band excluded along convex edges
    @property
    def tube_radius_m(self) -> float: ...  # how far along the edge, past the seam's ends, points are read
    @property
    def min_face_points(self) -> int: ...  # fewer points on the adjacent face: it places nothing
    @property
    def min_edge_points(self) -> int: ...  # fewer points just inside an edge: it places nothing
    @property
    def max_edge_strays(self) -> float: ...  # more density beyond an edge (share of that inside): nothing
    @property
    def edge_pitch_factor(self) -> float: ...  # an edge's sampling error, in point pitches on its face
    @property
    def tilt_prior_deg(self) -> float: ...  # standard deviation of a face's tilt off the map [deg]


@dataclass(frozen=True)
class EdgePlacement:
    """The best edge found for an unseen face: the adjacent face ``g`` whose edge it is, the edge's offset b
    along the face's normal from the map [m] and its standard error [m], g's noise scale [m], the points near
    the edge and how many cameras' edges were combined."""

    g: str
    b: float
    se: float
    scale: float
    count: int
    cameras: int


def place_from_edge(
    n: FloatArray,
    d: float,
    part: Part,
    face_name: str,
    skip: str,
    seam: tuple[FloatArray, FloatArray],
    table_z: float,
    away: Callable[[FloatArray], BoolArray],
    points: Points,
    crop: Box,
    o: EdgeOptions,
) -> EdgePlacement | str:
    """Place the unseen face ``face_name`` of ``part`` (plane n . p = d from the map, outward unit normal n (3,))
    from the edge where an adjacent face of the same part, seen, ends across it: the stretch of that edge
    alongside ``seam`` (its start and end (3,)). ``skip``: a face not to read (the joint's end face); ``away``
    masks the points (n, 3) far enough from the joint's other part; ``points`` reads the cloud; ``crop``: where
    the cloud was cropped (an edge there is the crop's, not the part's). The adjacent faces are tried nearest
    first; each camera's edge on its own, combined by inverse variance. Returns the placement, or why none."""
    search = 2.0 * o.map_tolerance_m  # the edge may lie as far from the map as a fitted face may drift [m]
    depth = float(part.box.size["xyz".index(face_name[1])]) if part.is_box else extent_behind(part, n, d)
    lo = max(-2.0 * search, -depth + o.edge_band_m)  # the window along u, inside ...
    hi = search + 3.0 * max(EDGE_BLURS) + o.edge_band_m  # ... and beyond the edge [m]
    gate = o.map_tolerance_m + 3.0 * o.sensor_sigma_m
    best: EdgePlacement | None = None
    why: list[str] = []
    mid = 0.5 * (seam[0] + seam[1])
    tilt = np.tan(np.radians(o.tilt_prior_deg))
    edges = []
    for g in adjacent_faces(part, face_name):
        n_g, d_g = part.face_plane(g)
        if g == skip or on_table(n_g, d_g, table_z, o.map_tolerance_m):
            continue  # the joint's end face, or never seen
        q0, e = plane_intersection(n, d, n_g, d_g, mid)
        reach = float(np.linalg.norm((mid - q0) - float(e @ (mid - q0)) * e))  # seam to edge line [m]
        edges.append((reach, g, n_g, d_g, q0, e))
    for reach, g, n_g, d_g, q0, e in sorted(edges, key=lambda x: x[0]):
        # The face is carried from its edge to the seam: a tilt within the prior moves it by tilt x reach, so an
        # edge that far cannot place it better than the best one found.
        if best is not None and tilt * reach >= best.se:
            continue
        # Points near the edge line, alongside the seam (its ends projected on the edge, +- the tube radius).
        s_ends = sorted(float(e @ (p - q0)) for p in seam)
        e_lo, e_hi = s_ends[0] - o.tube_radius_m, s_ends[1] + o.tube_radius_m
        P, cam, ok, front = points(q0 + e_lo * e, q0 + e_hi * e, float(np.hypot(max(-lo, hi), gate)))
        u = P @ n - d  # along the face's outward normal: the adjacent face's points end at u = 0
        r_g = P @ n_g - d_g
        # A facet of a corner radius (a tube's rounded edge): only a camera in front of the face sees the round out
        # to the face's plane, sharply; one that sees it blurred looks from behind the face, at its silhouette.
        # A camera behind the face sees the round's silhouette, wherever the round meets the face: only the cameras
        # in front of it read a facet's edge (where their centres are known; else the blur below tells).
        rounded = abs(float(n_g @ n)) > _ROUND_COS
        region = ok & away(P) & (u > lo) & (u < hi) & along_edge(part, face_name, g, P, o.edge_band_m)
        if rounded:
            region &= front
        sel = region & (np.abs(r_g) < gate)
        if np.count_nonzero(sel) < o.min_face_points:
            continue
        start = histogram_mode(r_g[sel], max(0.002, o.sensor_sigma_m))
        fit = robust_offset(r_g[sel], cam[sel], start)
        on = region & (np.abs(r_g - fit.offset) < 2.5 * max(fit.scale, 1e-4))
        if np.count_nonzero(on) < o.min_face_points:
            continue
        # Each camera's edge on its own (incidence, sampling and calibration differ between cameras), with its
        # standard error: the likelihood's and the sampling of the surface (points land on a pixel grid: with
        # the grid nearly parallel to the edge, every row ends at the same phase).
        uu, cc = u[on], cam[on]
        along = P[on] @ e
        cams, counts = np.unique(cc, return_counts=True)
        per_cam: list[tuple[float, float]] = []
        faults: list[tuple[int, str]] = []
        for c, n_c in zip(cams, counts, strict=True):
            if n_c < o.min_face_points:
                continue
            mine = cc == c
            edge = edge_fit(uu[mine], lo, hi, -search, search)
            b = edge.b if np.isfinite(edge.b) else 0.0
            fault = edge_fault(edge, g, search, at_cut(crop, q0 + b * n, n, edge.blur, o.edge_band_m), o)
            if not fault and rounded and edge.blur >= ROUND_BLUR_M:
                fault = (
                    f"the edge of {g} turns into the face round a corner radius and is blurred over "
                    f"{1000 * edge.blur:.1f} mm: seen from behind the face, its silhouette lies inside the round"
                )
            if fault:
                faults.append((int(n_c), fault))
                continue
            pitch = float(np.sqrt(edge.pitch * max(float(np.ptp(along[mine])), 1e-3)))  # on face g [m]
            per_cam.append((edge.b, float(np.hypot(edge.se, o.edge_pitch_factor * pitch))))
        if not per_cam:
            if faults:
                why.append(max(faults)[1])
            continue
        b_g, se_g = combine(per_cam)
        se_g = float(np.hypot(se_g, tilt * reach))
        if best is None or se_g < best.se:
            best = EdgePlacement(g, b_g, se_g, max(fit.scale, 1e-4), len(uu), len(per_cam))
    if best is not None:
        return best
    if why:
        return "its edge is not defined well enough: " + "; ".join(why)
    return "no edge of it is seen either: not seen or not there"


def edge_fault(edge: EdgeFit, g: str, search: float, cut: bool, o: EdgeOptions) -> str:
    """Why the edge of the adjacent face ``g``, searched ``search`` [m] about the map, does not define the
    unseen face (``cut``: it lies where the cloud stops), or "" when it does."""
    if not np.isfinite(edge.b) or not np.isfinite(edge.pitch) or edge.n_edge < o.min_edge_points:
        return f"the edge of {g} is defined by {edge.n_edge} points (needs {o.min_edge_points})"
    if cut:
        return f"the edge of {g} lies where the cloud stops (the workspace's boundary?)"
    if edge.at_limit or not np.isfinite(edge.se):
        return (
            f"the edge of {g} lies at the limit of the {1000 * search:.0f} mm searched about the map "
            "(no end of the points there: part moved, or the points stop there)"
        )
    if edge.blur >= max(EDGE_BLURS):
        return f"the edge of {g} is blurred over {1000 * edge.blur:.1f} mm (seen at grazing incidence only)"
    if not edge.strays <= o.max_edge_strays:  # NaN too: no density inside the edge to compare with
        return (
            f"the edge of {g} has {edge.strays:.0%} of its density beyond it (allowed "
            f"{o.max_edge_strays:.0%}): flying pixels or another surface"
        )
    return ""


def at_cut(crop: Box, p: FloatArray, n: FloatArray, blur: float, band: float) -> bool:
    """Whether the boundary of ``crop`` lies within ``band`` (and 3 ``blur``) [m] of ``p`` (3,) ahead along ``n``
    (3,): where the points stop because the cloud does, not the part."""
    _, s_out = line_box_span(p, n, crop)
    tol = band + 3.0 * (blur if np.isfinite(blur) else 0.0)
    return bool(np.isfinite(s_out) and abs(s_out) < tol)


def on_table(n: FloatArray, d: float, table_z: float, tol: float) -> bool:
    """Whether the plane n . p = d is a downward face resting on the table (within ``tol`` [m])."""
    return float(n @ _Z) < -0.9 and abs(d + table_z) < tol


def adjacent_faces(part: Part, face: str) -> list[str]:
    """The faces of ``part`` that share an edge with ``face`` (a box: the four not parallel to it, in
    :data:`BOX_FACES` order; any other body: those whose polygons share two vertices with it, in face order)."""
    if part.is_box:
        k_f = "xyz".index(face[1])
        return [g for g in BOX_FACES if "xyz".index(g[1]) != k_f]
    body = part.body
    assert isinstance(body, Polyhedron)
    mine = set(body.faces[body.names.index(face)])
    return [g for g, f in zip(body.names, body.faces, strict=True) if g != face and len(mine & set(f)) >= 2]


def along_edge(part: Part, f: str, g: str, P: FloatArray, band: float) -> BoolArray:
    """Points (n, 3) alongside the edge where faces ``f`` and ``g`` of ``part`` meet: their coordinate along the
    edge inside its span shrunk by ``band`` [m] (a box: along its third axis, inside the box so shrunk)."""
    if part.is_box:
        box = part.box
        free = ("xyz".index(f[1]), "xyz".index(g[1]))
        q = (P - box.center) @ box.X_AB[:3, :3]
        ok = np.ones(len(P), bool)
        for j in range(3):
            if j not in free:
                ok &= np.abs(q[:, j]) <= 0.5 * float(box.size[j]) - band
        return ok
    body = part.body
    assert isinstance(body, Polyhedron)
    shared = sorted(set(body.faces[body.names.index(f)]) & set(body.faces[body.names.index(g)]))
    ends = body.vertices[shared]
    e = ends[-1] - ends[0]
    e /= max(float(np.linalg.norm(e)), 1e-300)
    s = ends @ e
    along = P @ e
    return np.asarray((along >= float(s.min()) + band) & (along <= float(s.max()) - band))


def combine(estimates: list[tuple[float, float]]) -> tuple[float, float]:
    """Inverse-variance mean of (value, standard error) pairs and its standard error, inflated by the Birge
    ratio sqrt(chi^2 / (k - 1)) when the values scatter more than their errors say. Estimates whose errors are all
    infinite carry no weight: (nan, inf)."""
    v = np.array([e[0] for e in estimates])
    w = 1.0 / np.square(np.maximum([e[1] for e in estimates], 1e-9))
    if not w.sum() > 0.0:
        return float("nan"), float("inf")
    mean = float(w @ v / w.sum())
    se = float(1.0 / np.sqrt(w.sum()))
    if len(v) > 1:
        se *= max(1.0, float(np.sqrt(w @ (v - mean) ** 2 / (len(v) - 1))))
    return mean, se
