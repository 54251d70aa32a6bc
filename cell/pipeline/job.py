"""What is asked of a weld job, as one frozen value: built once (by the command line) and handed to
:func:`cell.pipeline.weld` or :func:`cell.pipeline.turnover.weld_part` as it is."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

Noise = Literal["none", "realistic"]  # the depth sensors' error model off or on
RescanAsked = Literal["none", "low", "all"]  # which seams are re-scanned up close
Sides = Literal["first", "all"]  # side A alone, or the part turned over for the seams left against the table


@dataclass(frozen=True)
class WeldJob:
    """The options of one weld job; None leaves the scenario's own setting.

    method : the locator (``paper``, ``ransac``, ``ours``). noise : overrides the scenario's sensor noise.
    rescan : overrides ``rescan.mode``. execute : drive the arm (False: a preview, nothing moves). gui : show the
    simulator's window. sides : ``first`` (the part as it lies) or ``all`` (turned over for the rest).
    """

    method: str | None = None
    noise: Noise | None = None
    rescan: RescanAsked | None = None
    execute: bool = True
    gui: bool = False
    sides: Sides = "all"
