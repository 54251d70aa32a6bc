"""Which seams a camera above the table can see: a seam against the table cannot be seen (nor welded) as it
lies.

No axis names are assumed for the parts: a weld face is "on the table" when its actual outward normal points
down (against the robot frame's +z, the direction in which ``table_z`` is measured) and the face lies at the
table top.
"""

from __future__ import annotations

import numpy as np

from cell.types import Box, Joint, WeldMap

UNDERSIDE_REASON = "underside: the seam lies against the table; flip the part to weld it"


def _face_on_table(box: Box, face: str, table_z: float, tol_m: float, down_cos: float) -> bool:
    n, _ = box.face_plane(face)
    if float(n[2]) > -down_cos:  # the outward normal does not point down into the table
        return False
    axis = "xyz".index(face[1])
    sign = 1.0 if face[0] == "+" else -1.0
    corners = box.corners()
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    on_face = corners[signs[:, axis] == sign]  # the face's 4 corners (Box.corners() bit order)
    return bool(np.all(np.abs(on_face[:, 2] - table_z) <= tol_m))


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
        if _face_on_table(weldmap_R.part(name).box, face, table_z, tol_m, down_cos):
            return False, UNDERSIDE_REASON
    return True, ""
