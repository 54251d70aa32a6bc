"""Which found seams must not be welded? The screen after the locator, turning seams into reasons.

For the pipeline, after the locator: :func:`screen` turns a found seam into NOT_FOUND / OCCLUDED, with the
reason, when its part is missing (:func:`cell.perception.align.checks.check_parts_seen`), when an object the
map does not know lies over it (:func:`foreign_points`), or when the locator itself had almost no confidence in it.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from cell.config.perception import ScreenOptions
from cell.geometry import FloatArray
from cell.types import Cloud, Reason, SeamEstimate, SeamScene, SeamStatus, VoxelTable, WeldMap
from cell.voxels import in_box


def foreign_points(
    weldmap_R: WeldMap,
    dense: Cloud,
    p_start: FloatArray,
    p_end: FloatArray,
    table_z: float,
    options: ScreenOptions | None = None,
    voxels: VoxelTable | None = None,
) -> int:
    """How many points of ``dense`` (R) within ``radius_m`` of the segment p_start-p_end (3,) [m] lie further
    than ``margin_m`` from every part and fixture of the map and above the table: an object the map does not know.

    voxels : where the voxels of ``dense`` lie in it when it is in voxel order: only the points of the voxels
    about the segment are looked at (the same count, without a pass over the whole cloud)."""
    o = options if options is not None else ScreenOptions()
    a, b = np.asarray(p_start, float), np.asarray(p_end, float)
    ab = b - a
    lo, hi = np.minimum(a, b) - o.radius_m, np.maximum(a, b) + o.radius_m
    P = np.asarray(dense.points) if voxels is None else np.asarray(dense.points)[in_box(voxels, lo, hi)]
    box = np.all((lo <= P) & (hi >= P), axis=1)
    Q = P[box]
    t = np.clip((Q - a) @ ab / max(float(ab @ ab), 1e-12), 0.0, 1.0)
    near = np.linalg.norm(Q - (a + t[:, None] * ab), axis=1) <= o.radius_m
    Q = Q[near & (Q[:, 2] > table_z + o.margin_m)]
    for part in (*weldmap_R.parts, *weldmap_R.fixtures):  # the map's fixtures are known too: not occluders
        Q = Q[~part.contains(Q, o.margin_m)]
    return len(Q)


def screen(
    scene: SeamScene,
    estimates: tuple[SeamEstimate, ...],
    missing: Mapping[str, str],
    options: ScreenOptions | None = None,
) -> tuple[SeamEstimate, ...]:
    """The locator's estimates with the seams that must not be welded taken out, each with its reason.

    missing : part name -> reason (from :func:`~cell.perception.align.checks.check_parts_seen`): every seam
    of such a part is NOT_FOUND, whatever the locator or the visibility check said. A seam (found or not) with at
    least ``min_foreign`` foreign points near it (map seam when not found) is OCCLUDED. A found seam with
    confidence below ``min_confidence`` is NOT_FOUND.
    """
    o = options if options is not None else ScreenOptions()
    out = []
    for est in estimates:
        seam = scene.weldmap.seam(est.id)
        joint = scene.joints.get(est.id)
        parts = (joint.abutting, joint.receiving) if joint is not None else ()
        part = next((n for n in parts if n in missing), None)
        if part is not None:
            out.append(SeamEstimate(est.id, SeamStatus.NOT_FOUND, missing[part], code=Reason.PART_MISSING))
            continue
        if est.status is SeamStatus.NOT_VISIBLE:
            out.append(est)
            continue
        n = foreign_points(scene.weldmap, scene.dense, seam.p_start, seam.p_end, scene.table_z, o, scene.dense_voxels)
        if n >= o.min_foreign:
            out.append(
                SeamEstimate(
                    est.id,
                    SeamStatus.OCCLUDED,
                    f"occluded: {n} points of an object the map does not know lie within "
                    f"{o.radius_m * 1000:.0f} mm of the seam (a clamp, a cable?): clear it and re-scan",
                    code=Reason.OCCLUDED,
                )
            )
            continue
        if est.status is SeamStatus.FOUND and est.confidence < o.min_confidence:
            out.append(
                SeamEstimate(
                    est.id,
                    SeamStatus.NOT_FOUND,
                    f"too uncertain to weld: confidence {est.confidence:.2f} < {o.min_confidence:.2f} ({est.reason})",
                    code=Reason.LOW_CONFIDENCE,
                )
            )
            continue
        out.append(est)
    return tuple(out)
