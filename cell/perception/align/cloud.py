"""Where a welding map lies in a brought cloud, levelled (frame L: the table's normal +z, the table at one height):
the staged ICP from a nominal placement, challenged by the height image's best pose unlike it; a global
registration (:mod:`cell.perception.align.placement`) when there is no placement or it fits poorly. Values in,
values out (docs/locate.md)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from cell.errors import AlignmentError, AlignmentFailure, CellError
from cell.geometry import FloatArray
from cell.perception.align.fit import Alignment, align_map, sample_map, surface_fit
from cell.perception.align.placement import DISTINCT_DEG, DISTINCT_M, fpfh_candidates, height_candidates
from cell.scenario import PerceptionSpec
from cell.types import Cloud, WeldMap

FRAME = "R"  # the stages' name for the frame they work in (for a brought cloud, the levelled frame L)
MARGIN_M = 0.1  # the crop around the placed map's bounds, horizontally and above [m]
POOR_FITNESS = 0.6  # a fit from the nominal placement below this fitness is retried from a global registration
CHALLENGE_MARGIN = 1.05  # a fit elsewhere must explain this many times the placement's fit's points to replace it
PRESCORE, PRESCORE_BAND_M = 0.7, 0.01  # ... and before its ICP this share of them, within this band


@dataclass(frozen=True)
class CloudPlacement:
    """Where the map was found in the levelled cloud: ``X_LM0`` the start pose (4, 4) its ``alignment`` refined
    (the alignment's ``X_RR_corr @ X_LM0`` is the map's pose; None: no placement and none found), or the
    ``error`` when none aligned (``alignment`` None)."""

    X_LM0: FloatArray | None
    alignment: Alignment | None
    error: CellError | None = None


def crop_bounds(map_L: WeldMap) -> tuple[FloatArray, FloatArray]:
    """(lo, hi) (3,) [m]: the placed map's bounds grown by MARGIN_M (its frame)."""
    v = np.vstack([p.vertices() for p in map_L.parts])
    return v.min(axis=0) - MARGIN_M, v.max(axis=0) + MARGIN_M


def crop_mask(P_L: FloatArray, above: np.ndarray, map_L: WeldMap) -> np.ndarray:
    """Points above the table within :func:`crop_bounds` (not below: the table is cut)."""
    lo, hi = crop_bounds(map_L)
    return above & np.all((lo <= P_L) & (hi >= P_L), axis=1)


def place_map(
    P_L: FloatArray,
    above: np.ndarray,
    weldmap: WeldMap,
    table_z: float,
    X_LM0: FloatArray | None,
    spec: PerceptionSpec,
    viewpoint_L: FloatArray | None,
    rng: np.random.Generator,
    progress: Callable[[str], None] = lambda _: None,
) -> CloudPlacement:
    """The map's placement in the levelled points P_L (n, 3) [m] (``above``: those above the table): aligned by
    the staged ICP from ``X_LM0`` (the nominal placement put flat on the table, None: none given); a fit of at
    least POOR_FITNESS is challenged by the height image's best pose unlike it, which replaces it when it explains
    CHALLENGE_MARGIN times the points; a poorer fit, or none, is retried from a global registration, whose best
    candidate replaces it when it explains more points. ``progress`` hears what was done beyond the first ICP."""
    alignment: Alignment | None = None
    error: CellError | None = None
    count = 0.0
    if X_LM0 is not None:
        crop = crop_mask(P_L, above, weldmap.transformed(X_LM0, FRAME))
        try:
            alignment = align_map(weldmap.transformed(X_LM0, FRAME), Cloud(P_L[crop], FRAME), spec)
            count = alignment.fitness * int(crop.sum())
        except AlignmentError as e:
            error = e
    if alignment is not None and X_LM0 is not None and alignment.fitness >= POOR_FITNESS:
        # A placement turned far off settles on a wrong fit that the checks pass (the tee turned by 180 degrees
        # fits 0.78 of its points): the height image's best pose unlike it must not explain clearly more points.
        other = _challenger(P_L, above, weldmap, table_z, spec, alignment.X_RR_corr @ X_LM0)
        if other is not None and other[2] > CHALLENGE_MARGIN * count:
            progress(
                f"the placement was far off: a fit elsewhere explains {other[2] / max(count, 1.0):.0%} of its points"
            )
            X_LM0, alignment = other[0], other[1]
    elif alignment is None or alignment.fitness < POOR_FITNESS:
        progress("global registration of the map (height image, FPFH + RANSAC)")
        best = _global(P_L, above, weldmap, table_z, viewpoint_L, rng, spec)
        if best is not None and (alignment is None or best[2] > count):
            X_LM0, alignment, error = best[0], best[1], None
        elif alignment is None and error is None:
            error = AlignmentError(
                "no placement of the map fits the cloud (global registration: no candidate aligned)",
                code=AlignmentFailure.LOW_FITNESS,
            )
    return CloudPlacement(X_LM0, alignment, error)


def _aligned(
    P_L: FloatArray, above: np.ndarray, weldmap: WeldMap, X0: FloatArray, spec: PerceptionSpec
) -> tuple[FloatArray, Alignment, float] | None:
    """(X0, its alignment, the points it explains: fitness times the points of its crop), or None when the staged
    ICP from X0 fails."""
    crop = crop_mask(P_L, above, weldmap.transformed(X0, FRAME))
    try:
        fit = align_map(weldmap.transformed(X0, FRAME), Cloud(P_L[crop], FRAME), spec)
    except AlignmentError:
        return None
    return X0, fit, fit.fitness * int(crop.sum())


def _global(
    P_L: FloatArray,
    above: np.ndarray,
    weldmap: WeldMap,
    table_z: float,
    viewpoint_L: FloatArray | None,
    rng: np.random.Generator,
    spec: PerceptionSpec,
) -> tuple[FloatArray, Alignment, float] | None:
    """The best global candidate (:mod:`cell.perception.align.placement`) as aligned by the staged ICP: the one
    that explains the most points of the cloud (:func:`_aligned`); None when none aligns. The height-image search
    first; FPFH + RANSAC only when none of its candidates fits well (on the real scans FPFH proposed the part
    turned by 180 degrees and took 5 s; the height image 0.3 s, right every time)."""
    best: tuple[FloatArray, Alignment, float] | None = None
    searches = (
        lambda: height_candidates(P_L[above], weldmap, table_z),
        lambda: fpfh_candidates(P_L[above], weldmap, table_z, viewpoint_L, rng),
    )
    for search in searches:
        for X0 in search():
            fit = _aligned(P_L, above, weldmap, X0, spec)
            if fit is not None and (best is None or fit[2] > best[2]):
                best = fit
        if best is not None and best[1].fitness >= POOR_FITNESS:
            break  # the height image's fit is good: FPFH is not asked
    return best


def _challenger(
    P_L: FloatArray, above: np.ndarray, weldmap: WeldMap, table_z: float, spec: PerceptionSpec, X_LM: FloatArray
) -> tuple[FloatArray, Alignment, float] | None:
    """The height image's best candidate unlike the fit ``X_LM`` (turned by more than DISTINCT_DEG or its parts'
    centre moved by more than DISTINCT_M), aligned; None when there is none or it does not align."""
    centre_M = np.mean([p.center for p in weldmap.parts], axis=0)

    def where(X: FloatArray) -> tuple[float, FloatArray]:
        return float(np.arctan2(X[1, 0], X[0, 0])), X[:3, :3] @ centre_M + X[:3, 3]

    yaw, c = where(X_LM)
    for X0 in height_candidates(P_L[above], weldmap, table_z):
        yaw0, c0 = where(X0)
        turn = abs((yaw0 - yaw + np.pi) % (2.0 * np.pi) - np.pi)
        if turn > np.radians(DISTINCT_DEG) or float(np.linalg.norm((c0 - c)[:2])) > DISTINCT_M:
            # Only a candidate that already explains a fair share of what the fit does is worth an ICP.
            if _explained(P_L, above, weldmap, X0) < PRESCORE * _explained(P_L, above, weldmap, X_LM):
                return None
            return _aligned(P_L, above, weldmap, X0, spec)
    return None


def _explained(P_L: FloatArray, above: np.ndarray, weldmap: WeldMap, X: FloatArray) -> float:
    """How many points of the crop about the map at X lie within PRESCORE_BAND_M of its surfaces."""
    map_L = weldmap.transformed(X, FRAME)
    crop = crop_mask(P_L, above, map_L)
    samples, normals = sample_map(map_L, PRESCORE_BAND_M / 2.0, PRESCORE_BAND_M / 2.0)
    fit, _ = surface_fit(P_L[crop], samples, normals, PRESCORE_BAND_M, PRESCORE_BAND_M / 2.0)
    return fit * int(crop.sum())
