"""Seams to weld from located seams: :func:`seam_tasks` (estimates and the aligned map -> :class:`SeamTask` in R)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from cell.geometry import FloatArray
from cell.types import SeamEstimate, SeamStatus, WeldMap
from cell.types.plan import SeamTask

if TYPE_CHECKING:
    from cell.types import Joint


def seam_tasks(
    estimates: Sequence[SeamEstimate],
    weldmap_R: WeldMap,
    joints: Mapping[str, Joint],
    table_z: float | None = None,
) -> tuple[SeamTask, ...]:
    """Tasks for the found seams: the located end points with the weld faces' normals from the aligned map.

    table_z : height of the table top in R [m]. A located end point below it (the locator's error on a seam that
    ends at the table) is moved along the seam up to the table top: a seam cannot run inside the table.
    """
    from cell.seams.joint import weld_faces  # the seams package stays out of the motion import chain

    out = []
    for est in estimates:
        if est.status is not SeamStatus.FOUND:
            continue
        n_a, _, n_b, _ = weld_faces(weldmap_R, joints[est.id])
        p0, p1 = np.array(est.p_start), np.array(est.p_end)
        if table_z is not None:
            p0, p1 = _clip_above(p0, p1, table_z), _clip_above(p1, p0, table_z)
        out.append(SeamTask(est.id, p0, p1, n_a, n_b))
    return tuple(out)


def _clip_above(p: FloatArray, other: FloatArray, z: float) -> FloatArray:
    """p moved along the line towards ``other`` until its height is at least z (unchanged if it already is or
    the line does not climb)."""
    if p[2] >= z or other[2] <= p[2]:
        return p
    f = min(1.0, (z - p[2]) / (other[2] - p[2]))
    return np.asarray(p + f * (other - p))
