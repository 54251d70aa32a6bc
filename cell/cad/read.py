"""A CAD file in: STEP through OpenCascade, STL/OBJ/PLY through trimesh; units from the STEP header or asked for
a mesh; bodies named as the map will name them (unique, legal DXF layer names). Frame ``M``, metres."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np

from cell.cad.model import Body, CadModel, Edge, Face
from cell.errors import MapError, MapUnitsError
from cell.weldmap import METRES_PER_UNIT
from cell.weldmap.units import NAMES, PLAUSIBLE_EXTENT_M

STEP_SUFFIXES = (".step", ".stp")
MESH_SUFFIXES = (".stl", ".obj", ".ply")
CAD_SUFFIXES = STEP_SUFFIXES + MESH_SUFFIXES
_ILLEGAL = re.compile(r"[<>/\\\":;?*|=',\s]+")  # not allowed in a DXF layer name (and no spaces: ids stay words)


def is_cad(path: Path) -> bool:
    """Whether ``path`` names a CAD file this package reads (by its suffix)."""
    return path.suffix.lower() in CAD_SUFFIXES


def _names(bodies: list[Body]) -> list[Body]:
    clean = [(_ILLEGAL.sub("_", b.name).strip("_") or "BODY").upper() for b in bodies]
    seen: dict[str, int] = {}
    for n in clean:
        seen[n] = seen.get(n, 0) + 1
    index: dict[str, int] = {}
    out = []
    for b, n in zip(bodies, clean, strict=True):
        index[n] = index.get(n, 0) + 1
        out.append(replace(b, name=f"{n}_{index[n]}" if seen[n] > 1 else n))
    return out


def _scaled(b: Body, k: float) -> Body:
    if k == 1.0:
        return b
    faces = tuple(Face(f.kind, f.normal, f.offset * k, f.origin * k, f.axis, f.radius * k, f.sign) for f in b.faces)
    edges = tuple(
        Edge(e.kind, e.points * k, e.faces, e.breaks, e.centre * k, e.axis, e.radius * k, e.start, e.sweep)
        for e in b.edges
    )
    return Body(b.name, faces, edges, b.vertices * k, b.triangles, b.triangle_face, b.layers)


def _mesh_units(extent_units: float, src: str) -> str:
    """The only units that give a mesh a welded part's size, else MapUnitsError naming the candidates."""
    lo, hi = PLAUSIBLE_EXTENT_M
    fits = [u for u in ("mm", "m", "in") if lo <= extent_units * METRES_PER_UNIT[u] <= hi]
    if len(fits) == 1:
        return fits[0]
    sizes = ", ".join(f"{NAMES[u]}: {extent_units * METRES_PER_UNIT[u]:.3g} m" for u in ("mm", "in", "m"))
    why = "more than one gives" if fits else "none gives"
    raise MapUnitsError(
        f"{src}: a mesh carries no units and its size ({extent_units:.4g} units across) is ambiguous ({sizes}; "
        f"{why} a welded part's size); say which with --units mm, --units m or --units in"
    )


def read_cad(path: str | Path, units: str | None = None) -> CadModel:
    """The bodies of a STEP, STL, OBJ or PLY file in metres.

    units : the file's units (``mm``, ``cm``, ``m``, ``in``). A STEP file declares its own (this wins over them,
    with a warning when the two differ); a mesh needs them unless only one of mm, m, in gives it a plausible size.
    Raises MapError (MapUnitsError for units) in one line naming the file and what would be valid.
    """
    path = Path(path)
    src = str(path)
    if units is not None and units not in METRES_PER_UNIT:
        raise MapUnitsError(f"unknown units {units!r}; valid: {', '.join(METRES_PER_UNIT)}")
    if not path.is_file():
        raise MapError(f"{src}: no such file")
    suffix = path.suffix.lower()
    warnings: list[str] = []
    if suffix in STEP_SUFFIXES:
        from cell.cad._ocp import read_step

        bodies, declared = read_step(path)  # in metres, OpenCascade having applied the declared units
        unit = declared
        if units is not None and units != declared:
            if declared in METRES_PER_UNIT:
                k = METRES_PER_UNIT[units] / METRES_PER_UNIT[declared]
                bodies = [_scaled(b, k) for b in bodies]
            warnings.append(f"{src}: the STEP file declares {declared}; read in {units} as asked")
            unit = units
    elif suffix in MESH_SUFFIXES:
        from cell.cad._trimesh import read_mesh

        raw = read_mesh(path)  # in file units
        extent = float(np.ptp(np.concatenate([b.vertices for b in raw]), axis=0).max())
        unit = units if units is not None else _mesh_units(extent, src)
        bodies = [_scaled(b, METRES_PER_UNIT[unit]) for b in raw]
    else:
        raise MapError(f"{src}: not a CAD file this cell reads; valid: {', '.join(CAD_SUFFIXES)}")
    return CadModel(tuple(_names(bodies)), src, unit, tuple(warnings))
