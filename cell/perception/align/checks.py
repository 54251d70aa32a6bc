"""Is the map fitted to the cloud where the part is? Checks after the alignment that turn a wrong fit into a reason:
a near-symmetric fit the cloud does not clearly reject (a ladder one rung off, a part turned by 180 degrees), and
parts the cloud does not cover (missing parts, or the map in the wrong place)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from cell.config.perception import CoverageOptions, SymmetryOptions
from cell.errors import AlignmentError, AlignmentFailure
from cell.geometry import FloatArray, make_pose, rpy_to_matrix, transform_points
from cell.perception.align.fit import Alignment, sample_map
from cell.perception.sky import in_sight, open_to_sky
from cell.scenario import PerceptionSpec
from cell.types import Cloud, WeldMap

_CONTACT_M = 0.003  # [m] a part's top this close to another part is covered by it (the joints' gaps are 0-2 mm)


@dataclass(frozen=True)
class Alternative:
    """A near-symmetry of the map and how the cloud judges it against the chosen fit.

    X : (4, 4) the alternative's pose change in R (aligned map -> alternative map), about the map's centre.
    label : what it is, in words (``"shifted 76.0 mm along x"``).
    self_overlap : share of the map's visible samples that the alternative puts on the map's own surfaces.
    support_chosen, support_alt : share of the samples only the chosen / only the alternative map has (the
        surfaces that tell them apart) with a cloud point within the band.
    n_distinct : how many such telling samples each side has (the smaller of the two).
    """

    X: FloatArray
    label: str
    self_overlap: float
    support_chosen: float
    support_alt: float
    n_distinct: int


def _candidates(weldmap_R: WeldMap, centre: FloatArray) -> list[tuple[FloatArray, str]]:
    """Rigid motions on the table that could map the drawing onto itself: 180 degrees about the vertical
    through ``centre``, and shifts by the offset between two box parts of the same size (a rung pitch)."""
    out: list[tuple[FloatArray, str]] = []
    T = make_pose(p=centre) @ make_pose(rpy_to_matrix((0.0, 0.0, math.pi))) @ make_pose(p=-centre)
    out.append((T, "turned 180 deg about the vertical"))
    parts = weldmap_R.parts
    shifts: list[FloatArray] = []
    for i, a in enumerate(parts):
        for b in parts[i + 1 :]:
            if a.is_box and b.is_box and np.allclose(np.sort(a.box.size), np.sort(b.box.size), atol=1e-4):
                d = b.box.center - a.box.center
                d[2] = 0.0
                if np.linalg.norm(d) > 1e-3:
                    shifts.append(d)
    # The smallest shift in each direction (a pitch), both ways.
    shifts.sort(key=lambda v: float(np.linalg.norm(v)))
    kept: list[FloatArray] = []
    for d in shifts:
        if all(abs(float(d @ k)) / (np.linalg.norm(d) * np.linalg.norm(k)) < 0.99 for k in kept):
            kept.append(d)
    for d in kept:
        for sign in (1.0, -1.0):
            axis = "xyz"[int(np.argmax(np.abs(d)))]
            out.append((make_pose(p=sign * d), f"shifted {sign * float(np.linalg.norm(d)) * 1000:.1f} mm along {axis}"))
    return out


def cloud_tree_of(cloud: Cloud) -> cKDTree:
    """The KD-tree both checks query a cloud's points with (unbalanced: built in half the time, and the checks
    only ask whether anything lies within their band, which any tree of the points answers the same)."""
    return cKDTree(np.asarray(cloud.points), balanced_tree=False, compact_nodes=False)


def alignment_alternatives(
    weldmap_R: WeldMap, cloud: Cloud, options: SymmetryOptions | None = None, cloud_tree: cKDTree | None = None
) -> list[Alternative]:
    """The aligned map's near-symmetries (self-overlap at least ``min_self_overlap``), each judged by the
    cloud on the samples that distinguish it from the chosen fit. ``weldmap_R`` is the map as aligned;
    ``cloud_tree`` : a KD-tree of the cloud's points when the caller has one (:func:`cloud_tree`)."""
    o = options if options is not None else SymmetryOptions()
    samples, _ = sample_map(weldmap_R, o.spacing_m, o.spacing_m)
    if len(samples) == 0 or len(cloud) == 0:
        return []
    # Unbalanced trees build in half the time and answer "anything within the band?" the same (every query here
    # asks only that, on every core).
    map_tree = cKDTree(samples, balanced_tree=False, compact_nodes=False)
    cloud_tree = cloud_tree_of(cloud) if cloud_tree is None else cloud_tree
    near_cloud = np.isfinite(cloud_tree.query(samples, distance_upper_bound=o.band_m, workers=-1)[0])
    out = []
    for T, label in _candidates(weldmap_R, samples.mean(axis=0)):
        moved = transform_points(T, samples)
        on_map = np.isfinite(map_tree.query(moved, distance_upper_bound=o.band_m, workers=-1)[0])
        self_overlap = float(on_map.mean())
        if self_overlap < o.min_self_overlap:
            continue
        # Samples only the chosen map has (the alternative puts nothing there) and only the alternative has.
        moved_tree = cKDTree(moved, balanced_tree=False, compact_nodes=False)
        only_chosen = ~np.isfinite(moved_tree.query(samples, distance_upper_bound=o.band_m, workers=-1)[0])
        only_alt = ~on_map
        alt_near = np.isfinite(cloud_tree.query(moved[only_alt], distance_upper_bound=o.band_m, workers=-1)[0])
        n = int(min(only_chosen.sum(), only_alt.sum()))
        s_chosen = float(near_cloud[only_chosen].mean()) if only_chosen.any() else 0.0
        s_alt = float(alt_near.mean()) if only_alt.any() else 0.0
        out.append(Alternative(T, label, self_overlap, s_chosen, s_alt, n))
    return out


def check_alignment_unique(
    weldmap_R: WeldMap,
    cloud: Cloud,
    alignment: Alignment,
    options: SymmetryOptions | None = None,
    cloud_tree: cKDTree | None = None,
) -> list[Alternative]:
    """Refuse a map fit that a near-symmetry of the map explains about as well (AlignmentError naming it).

    weldmap_R : the map *as aligned* (frame R); cloud : the dense cloud it was aligned to (frame R).
    An alternative whose telling surfaces the cloud supports at least as well as the chosen fit's, less
    ``min_margin``, makes the seams' identities ambiguous (a ladder one rung off puts every seam on its
    neighbour's joint). An exact symmetry (fewer than ``min_distinct`` telling samples: the drawing is the same
    either way) is not refused: every seam lands on an identical joint. Returns the alternatives examined.
    """
    o = options if options is not None else SymmetryOptions()
    alts = alignment_alternatives(weldmap_R, cloud, o, cloud_tree)
    for alt in alts:
        if alt.n_distinct < o.min_distinct:
            continue
        if alt.support_chosen - alt.support_alt < o.min_margin:
            better = "fits better" if alt.support_alt > alt.support_chosen else "fits almost as well"
            raise AlignmentError(
                f"ambiguous map alignment: the map {alt.label} {better} (cloud covers {alt.support_alt:.0%} of the "
                f"surfaces that tell the fits apart, against {alt.support_chosen:.0%} for the chosen fit, "
                f"fitness {alignment.fitness:.2f}); every seam could be on its neighbour's joint: place the part "
                "against its fixture stops and re-scan",
                code=AlignmentFailure.AMBIGUOUS,
                value=alt.support_chosen - alt.support_alt,
                needed=o.min_margin,
            )
    return alts


def part_coverage(
    weldmap_R: WeldMap,
    cloud: Cloud,
    spec: PerceptionSpec,
    band_m: float = 0.01,
    cloud_tree: cKDTree | None = None,
    eyes_R: FloatArray | None = None,
) -> dict[str, float]:
    """Part name -> share of its upward faces' samples (top, in R) with a cloud point within ``band_m`` [m].

    Upward faces open to the sky are seen by every camera above the table; a part that is on the table covers most
    of its top. Samples within :data:`_CONTACT_M` of another part are left out (covered by it: in contact, or under
    it), and so are those under any part's surface (:func:`~cell.perception.sky.open_to_sky`: an open tube's inner
    bottom wall, under its own top wall) and, when the sensors' centres ``eyes_R`` (k, 3) are known, those no sensor
    has in sight (:func:`~cell.perception.sky.in_sight`: a plate's top in a standing pipe's shadow). A part with no
    upward face left to sample (a gusset's sloped top, a plate wholly under others) is not judged: it has no entry.
    """
    spacing = max(spec.voxel_m / 2.0, 0.002)
    tree = None if not len(cloud) else cloud_tree_of(cloud) if cloud_tree is None else cloud_tree
    out = {}
    for part in weldmap_R.parts:
        one = WeldMap((part,), (), weldmap_R.units, weldmap_R.source, weldmap_R.frame)
        p, n = sample_map(one, spacing, spacing)
        top = p[n[:, 2] > 0.9]
        # Leave out where another part covers it (in contact) or stands over it.
        for other in weldmap_R.parts:
            if other is not part and len(top):
                top = top[~other.contains(top, _CONTACT_M)]
        top = top[open_to_sky(top, weldmap_R.parts)]
        if eyes_R is not None and len(top):
            top = top[in_sight(top, eyes_R, weldmap_R.parts)]
        if len(top) == 0:
            continue  # nothing of it faces up in the open: no top to judge by
        if tree is None:
            out[part.name] = 0.0
            continue
        out[part.name] = float(np.mean(np.isfinite(tree.query(top, distance_upper_bound=band_m, workers=-1)[0])))
    return out


def missing_parts(coverage: Mapping[str, float], min_coverage: float = 0.1, min_others: float = 0.4) -> dict[str, str]:
    """Parts whose top the cloud hardly covers while the best-covered part is well covered: name -> reason."""
    if not coverage or max(coverage.values()) < min_others:
        return {}
    return {
        name: f"part {name} is not in the cloud ({c:.0%} of its top seen, others up to "
        f"{max(coverage.values()):.0%}): missing or not placed"
        for name, c in coverage.items()
        if c < min_coverage
    }


def check_parts_seen(
    weldmap_R: WeldMap,
    cloud: Cloud,
    spec: PerceptionSpec,
    options: CoverageOptions | None = None,
    cloud_tree: cKDTree | None = None,
    eyes_R: FloatArray | None = None,
) -> dict[str, str]:
    """After alignment: refuse a map that does not lie where the cloud is; name the parts that are missing.

    weldmap_R : the map as aligned (frame R); cloud : the dense cloud (frame R); options : the coverage thresholds
    (:class:`~cell.config.CoverageOptions`); eyes_R : (k, 3) the sensors' centres when known (each part judged by
    the top they have in sight: :func:`part_coverage`). A part whose top is covered less than ``min_seen`` but more than
    ``min_coverage`` lies half on, half off the cloud: the map settled in a wrong place (part displaced beyond what
    alignment corrects), or the part runs out of the workspace: AlignmentError. So it is when more than half of the
    parts are missing. Returns the missing parts (covered less than ``min_coverage``): name -> reason; their seams
    must be NOT_FOUND.
    """
    o = options if options is not None else CoverageOptions()
    min_coverage, min_seen = o.min_coverage, o.min_seen
    coverage = part_coverage(weldmap_R, cloud, spec, cloud_tree=cloud_tree, eyes_R=eyes_R)
    partial = {n: c for n, c in coverage.items() if min_coverage <= c < min_seen}
    missing = missing_parts(coverage, min_coverage)
    if partial or len(missing) > len(coverage) / 2 or not coverage:
        worst = ", ".join(f"{n} {c:.0%}" for n, c in sorted(coverage.items(), key=lambda x: x[1])[:3])
        raise AlignmentError(
            f"the aligned map does not lie on the cloud: share of each part's top with points: {worst} (needs "
            f"{min_seen:.0%}, or under {min_coverage:.0%} for a missing part): part displaced beyond what the "
            "alignment corrects, running out of the workspace, or covered",
            code=AlignmentFailure.OFF_CLOUD,
            value=min(coverage.values(), default=0.0),
            needed=min_seen,
        )
    return missing


def check_alignment(
    weldmap_R: WeldMap,
    cloud: Cloud,
    alignment: Alignment,
    spec: PerceptionSpec,
    cloud_tree: cKDTree | None = None,
    eyes_R: FloatArray | None = None,
) -> dict[str, str]:
    """Both checks of an aligned map, :func:`check_alignment_unique` and :func:`check_parts_seen` (with the spec's
    ``symmetry`` and ``coverage`` options), side by side on two cores (scipy's KD-trees let go of the interpreter
    lock), reading one KD-tree of the cloud (``cloud_tree``, :func:`cloud_tree_of`, when the caller built it
    already); what they answer and raise is what they would one after the other: the uniqueness check's refusal
    first. ``eyes_R`` : (k, 3) the cameras' centres (:func:`check_parts_seen`). Returns the missing parts (name ->
    reason)."""
    tree = cloud_tree if cloud_tree is not None else cloud_tree_of(cloud) if len(cloud) else None
    with ThreadPoolExecutor(max_workers=1) as beside:
        seen = beside.submit(check_parts_seen, weldmap_R, cloud, spec, spec.coverage, tree, eyes_R)
        try:
            check_alignment_unique(weldmap_R, cloud, alignment, spec.symmetry, tree)
        except AlignmentError:
            seen.cancel()
            raise
        return seen.result()
