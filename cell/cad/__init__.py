"""CAD in: a STEP assembly (OpenCascade) or a mesh (trimesh) read into bodies, seams proposed where bodies meet,
and the result written as a welding map to review (DXF) with a picture of the proposals. Frame ``M``, metres.

The route and its rules: docs/maps.md ("Your own CAD part")."""

from cell.cad.export import write_proposals
from cell.cad.model import Body, CadModel, CurveKind, Edge, Face, SurfaceKind
from cell.cad.picture import draw_proposals
from cell.cad.proposals import GAP_M, MIN_LENGTH_M, Joint, Proposal, Proposals, Rejection, propose, summary_rows
from cell.cad.read import CAD_SUFFIXES, is_cad, read_cad
from cell.cad.roles import Role

__all__ = [
    "CAD_SUFFIXES",
    "GAP_M",
    "MIN_LENGTH_M",
    "Body",
    "CadModel",
    "CurveKind",
    "Edge",
    "Face",
    "Joint",
    "Proposal",
    "Proposals",
    "Rejection",
    "Role",
    "SurfaceKind",
    "draw_proposals",
    "is_cad",
    "propose",
    "read_cad",
    "summary_rows",
    "write_proposals",
]
