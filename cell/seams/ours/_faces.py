"""The weld faces our locator fits (frame R, metres): every plane of a pass fitted at once (offsets by the batched
biweight IRLS, :mod:`cell.seams._batch`), the weld faces' tilt step, and a face no camera sees placed from an edge
(:mod:`cell.seams._edge`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.seams._batch import fit_offsets, tilt_fits
from cell.seams._edge import place_from_edge
from cell.seams.ours._planes import Face, FitRequest, Fitted, Selection, Tilt, Tilted
from cell.seams.ours._points import Points, crop_box, gather
from cell.seams.ours.options import OursOptions
from cell.seams.sigma import TILT_TOLERANCE_RAD
from cell.types import Joint, MapSeam, Part, SeamScene

BoolArray = npt.NDArray[np.bool_]
IntArray = npt.NDArray[np.intp]


def fit_planes(requests: list[FitRequest], first: bool, o: OursOptions) -> list[list[Fitted | None]]:
    """Fit the offsets of every plane selected by ``requests`` (of one or several seams) at once
    (:func:`~cell.seams._batch.fit_offsets`; the first pass from a histogram mode with its scales measured again
    once settled, the later ones from the previous fit): for each request, each selection's fit. A side face
    whose fit keeps fewer points than it needs is not fitted (None)."""
    selections = [x for req in requests for x in req.selections]
    if not selections:
        return [[] for _ in requests]
    fit = fit_offsets(
        np.concatenate([x.r[x.fit] for x in selections]),
        [len(x.fit) for x in selections],
        np.concatenate([req.pts.cam[x.fit] for req in requests for x in req.selections]),
        max(req.pts.n_cams for req in requests),
        start=None if first else np.zeros(len(selections)),
        mode_half_width=o.map_tolerance_m + 3.0 * o.sensor_sigma_m,
        mode_bin=max(0.002, o.sensor_sigma_m),
        rescale_after=3 if first else 0,
    )
    fitted: list[Fitted | None] = []
    at = 0
    for j, x in enumerate(selections):
        weights = fit.weights[at : at + len(x.fit)]
        at += len(x.fit)
        if int(fit.count[j]) < min(x.need, len(x.fit)):
            fitted.append(None)
            continue
        se = float(fit.se[j]) * np.sqrt(len(x.fit) / len(x.sel))  # the stride stands for all the support
        fitted.append(Fitted(float(fit.offset[j]), se, max(float(fit.scale[j]), 1e-4), weights))
    out, at = [], 0
    for req in requests:
        out.append(fitted[at : at + len(req.selections)])
        at += len(req.selections)
    return out


def tilt(jobs: list[tuple[Selection, Fitted | None, Tilt, Points]], o: OursOptions) -> list[Tilted | None]:
    """Let fitted weld faces tilt a little off their normals (a Gaussian prior of ``tilt_prior_deg``): one
    weighted least-squares step of offset and tilt about each face's points' centroid (decorrelated), with
    the biweight weights of its offset fit, carried to the seam line (:func:`~cell.seams._batch.tilt_fits`, all
    faces at once). A job: the face's selection, its offset fit, the tilt step asked for and the seam's points;
    for each, the face tilted (None: not fitted, or too few weighted points)."""
    todo, r, u, v, w = [], [], [], [], []
    out: list[Tilted | None] = [None] * len(jobs)
    for i, (x, fitted, step, pts) in enumerate(jobs):
        if fitted is None or not isinstance(x.plane, Face):
            continue
        keep = fitted.weights > 0.0
        if np.count_nonzero(keep) < 4:
            continue
        face = x.plane
        idx = x.fit[keep]
        e_u = step.other_n - (step.other_n @ face.n) * face.n
        e_u /= np.linalg.norm(e_u)
        q = np.take(pts.xyz, idx, axis=1) - step.p0[:, None]
        todo.append((i, x, face, fitted, e_u, step.p0, step.t))
        r.append(x.r[idx] - fitted.offset)  # from the plane as fitted
        u.append(e_u @ q)
        v.append(step.t @ q)
        w.append(fitted.weights[keep])
    if not todo:
        return out
    fit = tilt_fits(
        np.concatenate(r),
        np.concatenate(u),
        np.concatenate(v),
        np.concatenate(w),
        [len(ri) for ri in r],
        float(np.tan(np.radians(o.tilt_prior_deg))),
        TILT_TOLERANCE_RAD,
    )
    for j, (i, x, face, fitted, e_u, p0, t) in enumerate(todo):
        # The plane r = c0 + a (u - uc) + b (v - vc) in the face's normal and offset (as its offset fit moved it).
        c0, a, b = float(fit.c0[j]), float(fit.a[j]), float(fit.b[j])
        m = face.n - a * e_u - b * t
        norm = float(np.linalg.norm(m))
        d_fitted = face.d + fitted.offset
        d = (d_fitted + c0 - a * (float(fit.uc[j]) + float(e_u @ p0)) - b * (float(fit.vc[j]) + float(t @ p0))) / norm
        # The offset's error (the fit's stride stands for all the support) and the tilt the prior did not let the
        # face follow (it moves the line by that much at the seam's ends, whatever the number of points); apart,
        # the tilt the points cannot pin within the parts' angular tolerance (for the sigma).
        se = float(fit.se0[j]) * np.sqrt(len(x.fit) / len(x.sel))
        out[i] = Tilted(m / norm, d, float(np.hypot(se, fit.bias0[j])), float(fit.tilt0[j]))
    return out


def face_from_edge(
    scene: SeamScene,
    face: Face,
    part: Part,
    face_name: str,
    skip: str,
    seam: MapSeam,
    joint: Joint,
    away: Callable[[FloatArray], BoolArray],
    rng: np.random.Generator,
    o: OursOptions,
) -> Face | str:
    """Place an unseen ``face`` of ``part`` from an edge (:func:`~cell.seams._edge.place_from_edge`, on
    ``edge_sample_share`` of the cloud); ``away`` masks the points (n, 3) far enough from the joint's other
    part. Returns the face placed (its standard error from the edge's own data), else why not."""

    def points(a: FloatArray, b: FloatArray, radius: float) -> tuple[FloatArray, IntArray, BoolArray, BoolArray]:
        pts = gather(scene, a, b, radius, 0.0, joint, rng, o, o.edge_sample_share)
        return pts.P, pts.cam, pts.ok, pts.facing(face.n, face.d)

    placed = place_from_edge(
        face.n,
        face.d,
        part,
        face_name,
        skip,
        (seam.p_start, seam.p_end),
        scene.table_z,
        away,
        points,
        crop_box(scene, o),
        o,
    )
    if isinstance(placed, str):
        return placed
    return replace(
        face,
        d=face.d + placed.b,
        se=placed.se,
        scale=placed.scale,
        count=placed.count,
        source=f"edge of {placed.g}",
        note=f"+-{1000 * placed.se:.2f} mm, {placed.cameras} camera{'s' if placed.cameras != 1 else ''}",
    )


def away_from(face: Face, band: float) -> Callable[[FloatArray], BoolArray]:
    """A mask of points (n, 3) at least ``band`` [m] in front of ``face``."""
    return lambda P: np.asarray(P @ face.n - face.d >= band)


def outside(part: Part, band: float) -> Callable[[FloatArray], BoolArray]:
    """A mask of points (n, 3) outside ``part``'s body grown by ``band`` [m]."""
    return lambda P: ~part.contains(P, margin=band)
