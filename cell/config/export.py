"""Options of the exports (:mod:`cell.export`): the robot program (KUKA KRL, ABB RAPID) and its weld commands."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

ArcMode = Literal["arctech", "signals"]
Controller = Literal["krl", "rapid"]


@dataclass(frozen=True)
class KrlOptions:
    """Options of the robot program (:func:`~cell.export.krl.krl_program`, :mod:`cell.export.rapid`).

    load_kg, load_cm_mm : payload on the flange (torch 1.8 kg + camera 0.1 kg, centre of mass from
        robots/build_kr5_arc.py): the values to enter with the tool data.
    arc : ``arctech`` writes KUKA.ArcTech's ARC_ON / ARC_SWI / ARC_OFF inline forms, each with its weld data set
        (from the segment's procedure) in the .dat; ``signals`` drives a power source without ArcTech through
        plain I/O (``cell krl check`` reads both).
    arc_on_output, arc_ok_input, arc_timeout_s : the plain-signal mode's output number (``$OUT``) that switches
        the arc on, input number (``$IN``) that says it burns, and how long in seconds the program waits for it
        before it switches the arc off and halts.
    tool_index, base_index : the TOOL_DATA and BASE_DATA index the program selects (``BAS(#TOOL, index)``,
        ``BAS(#BASE, index)``); the values to enter there are printed in the program's setup block. The base is the
        part: the aligned map.
    job_mode, param_set : ArcTech's JobModeId and ParamSetId of every weld data set (power-source specific names,
        as configured in WorkVisual).
    ptp_percent : PTP velocity/acceleration in percent of the axis maxima (the plan's PTP moves use the full
        limits).
    """

    load_kg: float = 1.9
    load_cm_mm: tuple[float, float, float] = (110.0, 0.0, 0.0)
    arc: ArcMode = "arctech"
    arc_on_output: int = 1
    arc_ok_input: int = 1
    arc_timeout_s: float = 2.0
    tool_index: int = 1
    base_index: int = 1
    job_mode: str = "GMAW synergic"
    param_set: str = "Set1"
    ptp_percent: int = 100

    def __post_init__(self) -> None:
        for key, lo, hi in (
            ("arc_on_output", 1, 4096),
            ("arc_ok_input", 1, 4096),
            ("tool_index", 1, 16),
            ("base_index", 1, 32),
            ("ptp_percent", 1, 100),
        ):
            v = getattr(self, key)
            if not lo <= v <= hi:
                raise ValueError(f"{key} must be in {lo}..{hi}, got {v}")
        if not 0.0 < self.arc_timeout_s <= 60.0:
            raise ValueError(f"arc_timeout_s must be in (0, 60] s, got {self.arc_timeout_s}")
        for key in ("job_mode", "param_set"):
            v = getattr(self, key)
            if not v or '"' in v or len(v) > 32:
                raise ValueError(f"{key} must be 1-32 characters without a double quote, got {v!r}")
