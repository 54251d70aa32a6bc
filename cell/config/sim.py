"""Options of the simulator (:mod:`cell.sim`): how the weld bead is drawn."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class BeadStyle:
    """How the weld bead is drawn: capsules of ``radius_m`` [m] along chords of about ``step_m`` [m]."""

    radius_m: float = 0.003
    step_m: float = 0.005
    rgba: tuple[float, float, float, float] = (0.9, 0.1, 0.1, 1.0)
