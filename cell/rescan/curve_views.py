"""What the close-ups of a doubtful curved seam look at: the stretches of the located curve whose sigma across it
is over the tolerance, cut into pieces that one close-up sees whole (each nearly straight: its chord within a few
millimetres of the curve), each a :class:`ViewTarget` that :func:`cell.rescan.viewpoint.plan_view` takes as it
takes a straight seam's (docs/curves-welding.md section 8). Frames: R; metres."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from cell.config.motion import ViewOptions
from cell.rescan.view_grid import ViewTarget
from cell.types.curve_estimate import CurveEstimate

MAX_PIECE_M = 0.06  # [m] a piece at most this long: the close-up's image holds it with its faces
MAX_SAGITTA_M = 0.004  # [m] and its chord at most this far from the curve
# [m] a curve's close-up stand-offs where the usual ones (ViewOptions.distances_m, 0.33-0.44 m) give no view the arm
# takes: a fillet under a rail, seen from below at its post, wants the camera nearer. A stereo camera measures this
# near with its disparity search shifted (the D4xx's "disparity shift": its far range, which a close-up does not
# need, is given up); its depth noise shrinks as the distance squared.
NEAR_DISTANCES_M = (0.30, 0.26, 0.22)


def near_view(view: ViewOptions) -> ViewOptions:
    """``view`` with the stand-offs of :data:`NEAR_DISTANCES_M` (the middle one preferred) and no fallback grid."""
    return replace(view, distances_m=NEAR_DISTANCES_M, preferred_distance_m=NEAR_DISTANCES_M[1], fallback_tilts_deg=())


def worst_first(est: CurveEstimate, max_sigma_m: float) -> list[ViewTarget]:
    """:func:`curve_view_targets` of ``est`` ordered by the largest sigma of their samples, largest first (the
    stretch the close-ups must fix first; ties in curve order)."""
    pieces = _pieces(est, max_sigma_m)
    sigma = np.asarray(est.sigma_m)
    order = sorted(range(len(pieces)), key=lambda k: -float(sigma[pieces[k][0] : pieces[k][1] + 1].max()))
    targets = curve_view_targets(est, max_sigma_m)
    return [targets[k] for k in order]


def curve_view_targets(est: CurveEstimate, max_sigma_m: float) -> list[ViewTarget]:
    """The view targets along ``est`` where its sigma across the seam exceeds ``max_sigma_m`` [m] (none when it
    nowhere does): each run of such samples cut into pieces at most :data:`MAX_PIECE_M` long whose chord stays
    within :data:`MAX_SAGITTA_M` of the samples; a piece's ends are its first and last samples, its faces' normals
    the mean of its samples'. Ids ``<seam>#<k>``, k from 1 along the curve."""
    out: list[ViewTarget] = []
    for i, j in _pieces(est, max_sigma_m):
        na = np.mean(est.n_abutting_R[i : j + 1], axis=0)
        nb = np.mean(est.n_receiving_R[i : j + 1], axis=0)
        out.append(
            ViewTarget(
                f"{est.id}#{len(out) + 1}", est.p_RS[i], est.p_RS[j], na / np.linalg.norm(na), nb / np.linalg.norm(nb)
            )
        )
    return out


def _pieces(est: CurveEstimate, max_sigma_m: float) -> list[tuple[int, int]]:
    """(first, last) sample indices of each piece of :func:`curve_view_targets`, in curve order."""
    p = np.asarray(est.p_RS)
    doubtful = np.asarray(est.sigma_m) > max_sigma_m
    out: list[tuple[int, int]] = []
    i, n = 0, len(p)
    while i < n:
        if not doubtful[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and doubtful[j + 1] and _fits(p, i, j + 1):
            j += 1
        if j > i:
            out.append((i, j))
        i = j + 1
    return out


def _fits(p: np.ndarray, i: int, j: int) -> bool:
    """Whether samples p[i..j] make one piece: no longer than the limit, its chord close to every sample."""
    a, b = p[i], p[j]
    length = float(np.linalg.norm(np.diff(p[i : j + 1], axis=0), axis=1).sum())
    if length > MAX_PIECE_M:
        return False
    ab = b - a
    ll = float(ab @ ab)
    if ll <= 0.0 or j - i < 2:
        return True
    t = np.clip((p[i + 1 : j] - a) @ ab / ll, 0.0, 1.0)
    return bool(np.max(np.linalg.norm(p[i + 1 : j] - (a + t[:, None] * ab), axis=1)) <= MAX_SAGITTA_M)


__all__ = ["MAX_PIECE_M", "MAX_SAGITTA_M", "NEAR_DISTANCES_M", "curve_view_targets", "near_view", "worst_first"]
