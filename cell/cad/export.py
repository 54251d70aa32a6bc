"""The proposals as a welding map to review (:func:`cell.weldmap.write_map`): parts, fasteners and fixtures,
proposed seams red, rejected ones on their own layer, each seam's joint and reason as a note."""

from __future__ import annotations

import math
from pathlib import Path

from cell.cad.model import CurveKind
from cell.cad.proposals import Proposal, Proposals
from cell.cad.roles import Role
from cell.weldmap import FASTENER_LAYER, FIXTURE_LAYER, DrawnBody, DrawnSeam, write_map


def note(s: Proposal) -> str:
    """What the map says of a seam beside its id: how it was found, and why it is not proposed."""
    text = f"{s.joint.value} joint, dihedral {math.degrees(s.dihedral):.1f} deg, {s.abutting} on {s.receiving}"
    return text + (f"; rejected: {s.rejected.value}" if s.rejected is not None else "; proposed from CAD contact")


def _seam(s: Proposal) -> DrawnSeam:
    c = s.curve
    kind = {CurveKind.LINE: "line", CurveKind.ARC: "arc", CurveKind.CURVE: "curve"}[c.kind]
    if c.kind == CurveKind.ARC:
        return DrawnSeam(
            s.id, kind, c.points, s.rejected is not None, note(s), c.centre, c.axis, c.radius, c.start, c.sweep
        )
    return DrawnSeam(s.id, kind, c.points, s.rejected is not None, note(s))


def write_proposals(found: Proposals, path: str | Path) -> Path:
    """Write the map of ``found`` to ``path`` (DXF, millimetres); returns it."""
    layer = {Role.PART: None, Role.FASTENER: FASTENER_LAYER, Role.FIXTURE: FIXTURE_LAYER}
    bodies = [
        DrawnBody(b.name, b.vertices, b.triangles, layer[r])
        for b, r in zip(found.model.bodies, found.roles, strict=True)
    ]
    return write_map(path, bodies, [_seam(s) for s in found.seams])
