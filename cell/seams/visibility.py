"""Which seams a camera above the table can see: a seam against the table (a weld face whose outward normal points
down, every vertex at the table top) cannot be seen nor welded as it lies. No axis names are assumed for the parts."""

from __future__ import annotations

import numpy as np

from cell.types import Joint, Part, WeldMap

UNDERSIDE_REASON = "underside: the seam lies against the table; flip the part to weld it"


def _face_on_table(part: Part, face: str, table_z: float, tol_m: float, down_cos: float) -> bool:
    """Whether the face's outward normal points down and every vertex of its polygon lies at the table top."""
    n, _ = part.face_plane(face)
    if float(n[2]) > -down_cos:  # the outward normal does not point down into the table
        return False
    return bool(np.all(np.abs(part.face_polygon(face)[:, 2] - table_z) <= tol_m))


def visibility(
    weldmap_R: WeldMap, joint: Joint, table_z: float, tol_m: float = 0.005, max_tilt_deg: float = 20.0
) -> tuple[bool, str]:
    """Whether the seam of ``joint`` can be seen from above, and why not.

    weldmap_R : the map in the robot frame R (+z up).
    table_z : height of the table top in R [m].
    tol_m : how far [m] a face may be from the table top and still lie on it.
    max_tilt_deg : how far a face normal may be from straight down and still face the table.
    Returns ``(True, "")`` or ``(False, reason)``.
    """
    down_cos = float(np.cos(np.radians(max_tilt_deg)))
    for name, face in ((joint.abutting, joint.face_abutting), (joint.receiving, joint.face_receiving)):
        if _face_on_table(weldmap_R.part(name), face, table_z, tol_m, down_cos):
            return False, UNDERSIDE_REASON
    return True, ""
