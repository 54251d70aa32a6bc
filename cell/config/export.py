"""Options of the exports (:mod:`cell.export`): the KUKA KRL program."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal


@dataclass(frozen=True)
class KrlOptions:
    """Options of the KRL program (:func:`~cell.export.krl.krl_program`).

    load_kg, load_cm_mm : payload on the flange ($LOAD: torch 1.8 kg + camera 0.1 kg, centre of mass from
        robots/build_kr5_arc.py).
    arc_markers : ``comment`` writes ``;ARC_ON``/``;ARC_OFF`` comment lines, ``call`` plain subroutine calls.
    ptp_percent : PTP velocity/acceleration in percent of the axis maxima (the plan's PTP moves use the full
        limits).
    """

    load_kg: float = 1.9
    load_cm_mm: tuple[float, float, float] = (110.0, 0.0, 0.0)
    arc_markers: Literal["comment", "call"] = "comment"
    ptp_percent: int = 100
