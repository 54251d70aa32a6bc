"""Turning the part for its second side (docs/flip.md): what the cell is told (``flip:``) and what only a
simulation knows (``simulation.flip_placement``: how far off the operator sets the turned part down)."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from cell.scenario.base import Model


class TackSpec(Model):
    """Tack welds side A lays before the turn, holding the parts together (docs/flip.md section 1a): ``count``
    tacks of ``length_mm`` each on its seams, before any full weld, when the part will be turned; none when 0."""

    count: Annotated[int, Field(ge=0, le=100)] = 0  # tacks per part before the turn
    length_mm: Annotated[float, Field(gt=0.0, le=100.0)] = 10.0  # each tack's length


class TurnoverSpec(Model):
    """Whether and how the part may be turned over for the seams its first side leaves against the table.

    allowed : false for a part too heavy (or too awkward) to turn: the seams left keep their reason.
    operator_s : the operator's time to turn the part and confirm [s], counted in the job's cycle time.
    tacks : tack welds side A lays before any full weld when the part will be turned (planned and welded: their
        time is part of side A's cycle time).
    max_tilt_deg : the largest lean of the turned part (resting on the hull facet under its centre of mass)
        accepted; a turn that leans more is not made.
    """

    allowed: bool = True
    operator_s: Annotated[float, Field(ge=0.0, le=7200.0)] = 120.0
    tacks: TackSpec = TackSpec()
    max_tilt_deg: Annotated[float, Field(ge=0.0, le=20.0)] = 5.0


class TurnoverPlacementSpec(Model):
    """How far off its nominal turned pose the operator sets the part down (ground truth only): a horizontal
    offset of ``offset_mm`` in a direction and a turn of ``rotation_deg`` about the vertical of a sign, both drawn
    from ``Scenario.rng("flip")``."""

    offset_mm: Annotated[float, Field(ge=0.0, le=200.0)] = 0.0  # horizontal placement error after the turn
    rotation_deg: Annotated[float, Field(ge=0.0, le=30.0)] = 0.0  # turn about the vertical after the turn
    cameras_lost: tuple[str, ...] = ()  # cameras that go dead at the turn: side B is seen without them
