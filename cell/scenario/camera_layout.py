"""Where ``cell init`` puts the fixed cameras: places about the part (:func:`camera_candidates`) and the choice among
them by the seams' faces each would see (:func:`choose_cameras`; docs/cell.md, "Your own part")."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from cell.geometry import FloatArray
from cell.types import WeldMap

CAMERA_SIDE_M = 0.85  # fixed camera to the point it looks at, horizontally [m] ...
CAMERA_ABOVE_TOP_M = 1.0  # ... and above the part's top [m] (the shipped cells' pair)
# A lower ring of places, for faces the upper one sees only near grazing (a web's side facing the robot):
# (horizontally [m], above the part's top [m], name suffix).
CAMERA_RINGS = ((CAMERA_SIDE_M, CAMERA_ABOVE_TOP_M, ""), (1.0, 0.6, "_low"))
CAMERA_SECTION_M = 1.6  # longest part one pair of fixed cameras covers [m]
CAMERA_UP = (0.0, 1.0, 0.0)  # portrait: the image's up is +y, its long side along x
# Where a fixed camera may stand about the point it looks at, by preference: the shipped pair (+x, -x), the far
# side (+y) and its diagonals, then the diagonals on the robot's side (the arm works in front, from -y) [deg from +x].
CAMERA_AZIMUTHS = (
    ("cam_right", 0.0),
    ("cam_left", 180.0),
    ("cam_far", 90.0),
    ("cam_far_right", 45.0),
    ("cam_far_left", 135.0),
    ("cam_near_right", -45.0),
    ("cam_near_left", -135.0),
)
# Where the eye-in-hand camera may look from its scan pose, shifted from the part's centre towards the robot (-y)
# [m]: the torch hangs below the image's centre, and a part imaged there is cut in two by it.
SCAN_TARGET_SHIFTS_M = (0.0, -0.1, -0.2)
MIN_FIXED_CAMERAS = 2  # per section, as the shipped cells: each face the splice sees from two sides


FaceSight = Callable[[WeldMap, float, Sequence[tuple[FloatArray, FloatArray, FloatArray]], Sequence[bool]], FloatArray]
"""(the map in W, the table top z [m], camera poses (eye, target, up) (3,) in W, whether each is the arm's camera
(its torch in view)) -> (poses, seams, 2) the worst incidence [deg] on each seam's face A and B from each pose, inf
where it does not see that face, nan for a seam against the table (:func:`cell.rescan.sight.pose_sight`: the
pipeline's view test, which this layer cannot import)."""


def camera_candidates(target_W: FloatArray, top_z: float, suffix: str = "") -> list[tuple[str, FloatArray, FloatArray]]:
    """(name, eye, target) (3,) [m] in W of every place a fixed camera may look at ``target_W`` from, about a part
    whose top is at ``top_z`` [m]: on each of :data:`CAMERA_RINGS`, in :data:`CAMERA_AZIMUTHS`' order."""
    out = []
    for side, above, ring in CAMERA_RINGS:
        for name, az in CAMERA_AZIMUTHS:
            a = math.radians(az)
            x, y = target_W[0] + side * math.cos(a), target_W[1] + side * math.sin(a)
            out.append((name + ring + suffix, np.round([x, y, top_z + above], 9), np.asarray(target_W, dtype=float)))
    return out


def choose_cameras(
    map_W: WeldMap,
    table_z: float,
    sections: Sequence[FloatArray],
    top_z: float,
    scan: tuple[FloatArray, FloatArray],
    sight: FaceSight,
) -> tuple[dict[str, tuple[FloatArray, FloatArray]], tuple[FloatArray, FloatArray], tuple[str, ...]]:
    """The fixed cameras looking at the ``sections``' centres (3,) in W from :func:`camera_candidates`' places, by
    the faces of the map's seams (in W, the table top at ``table_z`` [m]) they see (``sight``), and the seams whose
    faces neither they nor the eye-in-hand camera at its scan pose see: only the close-up will. The scan pose is
    ``scan`` (eye, target) with its target shifted by the first of :data:`SCAN_TARGET_SHIFTS_M` that sees the most
    faces past the torch.

    The shipped pair per section (+x, -x) when it sees every face some candidate place sees; else, greedily, the
    place that sees the most faces not yet seen (on a tie: at the smallest worst incidence, then in preference
    order); then, in a section with fewer than :data:`MIN_FIXED_CAMERAS`, the place that sees both faces of the
    most seams seen whole by fewer than two. The part's top is at ``top_z`` [m]."""
    cands = []  # (section, preference, name, eye, target)
    for i, target in enumerate(sections):
        names = camera_candidates(target, top_z, "" if len(sections) == 1 else f"_{i + 1}")
        cands += [(i, k, *c) for k, c in enumerate(names)]
    scans = [(scan[0], scan[1] + np.array([0.0, dy, 0.0])) for dy in SCAN_TARGET_SHIFTS_M]
    poses = [(e, t, np.array([0.0, 0.0, 1.0])) for e, t in scans] + [(e, t, np.array(CAMERA_UP)) for *_, e, t in cands]
    n_scan = len(scans)
    inc = sight(map_W, table_z, poses, [True] * n_scan + [False] * len(cands))
    visible = ~np.isnan(inc[0, :, 0])  # seams not against the table
    k_scan = int(np.argmax(np.isfinite(inc[:n_scan]).sum(axis=(1, 2))))  # the first of the most
    by_scan = np.isfinite(inc[k_scan])
    inc = inc[n_scan - 1 :]  # the candidates from index 1
    seen = np.isfinite(inc[1:])  # (candidates, seams, 2)
    wanted = seen.any(axis=0) & visible[:, None]
    pair = [k for k, c in enumerate(cands) if c[1] < 2]  # +x and -x: the shipped pair
    if np.all(seen[pair].any(axis=0) | ~wanted):
        chosen = pair
    else:
        chosen, covered = [], np.zeros_like(wanted)
        while np.any(wanted & ~covered):
            new = seen & wanted & ~covered
            gain = new.sum(axis=(1, 2))
            worst = np.where(new, inc[1:], 0.0).max(axis=(1, 2))
            best = int(np.lexsort((np.arange(len(cands)), worst, -gain))[0])
            chosen.append(best)
            covered |= seen[best]
        for i in range(len(sections)):
            while sum(cands[k][0] == i for k in chosen) < MIN_FIXED_CAMERAS:
                whole = seen.all(axis=2) & visible[None, :]  # (candidates, seams) both faces
                few = whole[chosen].sum(axis=0) < 2
                score = np.where([c[0] == i and k not in chosen for k, c in enumerate(cands)], (whole & few).sum(1), -1)
                if score.max() < 0:
                    break
                chosen.append(int(np.argmax(score)))
    covered = seen[chosen].any(axis=0) | by_scan
    only = tuple(s.id for j, s in enumerate(map_W.seams) if visible[j] and not covered[j].all())
    return {cands[k][2]: (cands[k][3], cands[k][4]) for k in sorted(chosen)}, scans[k_scan], only
