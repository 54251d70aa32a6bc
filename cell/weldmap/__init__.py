"""DXF welding map -> :class:`~cell.types.WeldMap` (frame ``M``, metres). The only package importing ezdxf.

What a welding map holds (docs/maps.md):

- seams: LINEs, LWPOLYLINEs (with their elevation) and 2D/3D POLYLINEs whose effective colour is red (ACI 1 or 10,
  BYLAYER on a red layer, BYBLOCK in a red INSERT through nested blocks, or true colour ``#FF0000``), or that lie
  on a seam layer; a polyline is a chain of straight seams ``<id>.1``, ``<id>.2``...; id from XDATA ``WELDCELL``
  (group 1000), else ``seam-<handle>`` (handles of the enclosing INSERTs first, joined by ``.``). Red arcs,
  circles, ellipses, splines and polyline bulges are listed as unsupported, with the reason;
- parts: 3DSOLID (ACIS), MESH, polyface/polygon-mesh POLYLINE bodies and groups of connected 3DFACEs, each fitted
  by an oriented box; named after the layer (as spelt in the layer table), or the block for a body on layer ``0``
  inside a block; fixtures (layers ``FIXTURE*``, ``CLAMP*``, ``JIG*``, ``STOP*`` by default, ``map.layers``)
  are obstacles, never parts; a part that is no box refuses the map only when it holds a seam;
- units from the caller (``--units`` / ``map.units``), else ``$INSUNITS`` (1 in, 4 mm, 5 cm, 6 m).

Modules: ``read`` (the order of the checks), ``_load`` (the file, ezdxf's errors and log), ``_walk`` (entities,
colours, INSERTs), ``_meshes`` (bodies' faces), ``boxfit`` (boxes from faces), ``roles`` (layers), ``units``,
``describe``. Every failure is a one-line :class:`~cell.errors.MapError` naming the file, the entity and the fix.
"""

from cell.weldmap._walk import RED_ACI, SEAM_APPID
from cell.weldmap.boxfit import BOX_TOL, fit_box
from cell.weldmap.describe import describe, touching
from cell.weldmap.read import MAX_COORD_M, read_map, summary
from cell.weldmap.roles import DEFAULT_FIXTURE_LAYERS, LayerPatterns, LayerRoles, body_role
from cell.weldmap.units import METRES_PER_UNIT, UNITS_BY_INSUNITS, resolve_units

__all__ = [
    "BOX_TOL",
    "DEFAULT_FIXTURE_LAYERS",
    "MAX_COORD_M",
    "METRES_PER_UNIT",
    "RED_ACI",
    "SEAM_APPID",
    "UNITS_BY_INSUNITS",
    "LayerPatterns",
    "LayerRoles",
    "body_role",
    "describe",
    "fit_box",
    "read_map",
    "resolve_units",
    "summary",
    "touching",
]
