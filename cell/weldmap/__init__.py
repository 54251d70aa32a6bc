"""DXF welding map -> :class:`~cell.types.WeldMap` (frame ``M``, metres), and a map written for review
(:func:`write_map`). The only package importing ezdxf.

Seams, parts, fixtures and units as docs/maps.md says; every failure is a one-line :class:`~cell.errors.MapError`
naming the file, the entity and the fix."""

from cell.weldmap._walk import RED_ACI, SEAM_APPID
from cell.weldmap.boxfit import BOX_TOL, fit_box
from cell.weldmap.describe import describe, touching
from cell.weldmap.read import MAX_COORD_M, read_map, summary
from cell.weldmap.roles import DEFAULT_FIXTURE_LAYERS, LayerPatterns, LayerRoles, body_role
from cell.weldmap.units import METRES_PER_UNIT, UNITS_BY_INSUNITS, resolve_units
from cell.weldmap.write import (
    FASTENER_LAYER,
    FIXTURE_LAYER,
    REJECTED_LAYER,
    SEAM_LAYER,
    DrawnBody,
    DrawnSeam,
    write_map,
)

__all__ = [
    "BOX_TOL",
    "DEFAULT_FIXTURE_LAYERS",
    "FASTENER_LAYER",
    "FIXTURE_LAYER",
    "MAX_COORD_M",
    "METRES_PER_UNIT",
    "RED_ACI",
    "REJECTED_LAYER",
    "SEAM_APPID",
    "SEAM_LAYER",
    "UNITS_BY_INSUNITS",
    "DrawnBody",
    "DrawnSeam",
    "LayerPatterns",
    "LayerRoles",
    "body_role",
    "describe",
    "fit_box",
    "read_map",
    "resolve_units",
    "summary",
    "touching",
    "write_map",
]
