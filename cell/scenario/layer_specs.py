"""``map.layers``: which DXF layers hold the parts, the fixtures and the seams (docs/maps.md)."""

from __future__ import annotations

from pydantic import Field

from cell.scenario.base import Model

Patterns = tuple[str, ...]


class LayerSpec(Model):
    """Shell-style layer name patterns (``CLAMP*``), case ignored like DXF layer names.

    A body is a fixture (an obstacle for the arm, never a part: never aligned, never welded) when its layer, or its
    block for a body on layer 0, matches ``fixtures``; else a part when ``parts`` is not given or matches; else it
    is ignored with a warning. A LINE or polyline is a seam when it is red or lies on a ``seams`` layer.
    """

    parts: Patterns | None = None  # layers (or blocks) of the parts; null: every body not on a fixture layer
    # layers (or blocks) of the fixtures: obstacles for the arm, never parts (cell.weldmap's defaults)
    fixtures: Patterns = Field(default=("FIXTURE*", "CLAMP*", "JIG*", "STOP*"))
    seams: Patterns = ()  # layers whose lines are seams whatever their colour (red lines always are)
