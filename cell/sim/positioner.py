"""The positioner in the simulator: its bodies (grey boxes: :func:`cell.positioner.bodies.positioner_parts`), moved
with whatever the faceplate carries by :func:`cell.sim.bodies.move_bodies` (docs/positioner.md, "Sensing and the
simulator")."""

from __future__ import annotations

from collections.abc import Iterable

from cell.sim.bodies import add_part
from cell.sim.quiet import BulletClient
from cell.types import Part

_RGBA = (0.35, 0.38, 0.42, 1.0)


def add_bodies(client: BulletClient, parts_W: Iterable[Part]) -> dict[str, int]:
    """Static bodies for the positioner's boxes in W; name -> body id."""
    return {p.name: add_part(client, p, _RGBA) for p in parts_W}
