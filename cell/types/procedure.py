"""Weld procedures (a WPS row): what the arc does along a seam, as values, selected per seam by the planner and
carried to the exporters, the simulator and the report. Units as a WPS states them (mm, deg, s, A, V, m/min); the
planner converts to metres where it builds paths."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

WeavePattern = Literal["none", "zigzag", "triangle", "circle"]
WeldDirection = Literal["as_drawn", "up", "down"]
JointType = Literal["T", "corner", "lap", "any"]
Position = Literal["PA", "PB", "PF", "PG", "any"]


@dataclass(frozen=True)
class Weave:
    """Oscillation of the torch while it travels along the seam: ``pattern`` (none: a straight bead; zigzag:
    across the seam with smooth turns, fading in and out; triangle: across on straight legs with sharp turns;
    circle: round a circle in the joint's cross-section; :mod:`cell.motion.process.weave`), full ``width_mm`` (peak to
    peak; the circle's diameter), ``frequency_hz``, dwell at each side ``dwell_s`` (left, right)."""

    pattern: WeavePattern = "none"
    width_mm: float = 0.0
    frequency_hz: float = 0.0
    dwell_s: tuple[float, float] = (0.0, 0.0)

    @property
    def active(self) -> bool:
        return self.pattern != "none" and self.width_mm > 0.0 and self.frequency_hz > 0.0


@dataclass(frozen=True)
class WeldPass:
    """One pass of a multi-pass weld: its offset from the root in the joint's cross-section [mm] (``lateral_mm``
    along the bisector's normal, towards face A positive; ``lift_mm`` along the bisector, out of the root) and its
    own travel speed (0: the procedure's)."""

    lateral_mm: float = 0.0
    lift_mm: float = 0.0
    travel_speed_mm_s: float = 0.0


@dataclass(frozen=True)
class WeldProcedure:
    """One weld procedure: where it applies, the arc's settings, the torch, the weave, the craters and passes.

    applies to: ``joint`` type, ``position`` and leg sizes ``leg_min_mm``..``leg_max_mm``.
    arc: ``process`` (e.g. "135 MAG", ISO 4063), ``wire`` (classification and diameter), ``gas``,
    ``current_a``, ``voltage_v``, ``wire_feed_m_min``, ``travel_speed_mm_s``.
    bead: ``leg_mm`` (fillet leg; throat = leg / sqrt(2) for a square fillet).
    torch: ``work_angle_deg``, ``travel_angle_deg`` (push positive), ``direction`` for vertical seams.
    craters: ``crater_start_s`` (hot start) and ``crater_end_s`` (crater fill) at the weld's ends, at rest.
    passes: one root pass at the root unless more are given.
    """

    name: str
    joint: JointType = "any"
    position: Position = "any"
    leg_min_mm: float = 0.0
    leg_max_mm: float = 1000.0
    process: str = "135 MAG"
    wire: str = "ISO 14341-A G3Si1, 1.0 mm"
    gas: str = "ISO 14175 M21 (Ar + 18 % CO2), 15 l/min"
    current_a: float = 190.0
    voltage_v: float = 21.5
    wire_feed_m_min: float = 7.0
    travel_speed_mm_s: float = 8.0
    leg_mm: float = 4.0
    work_angle_deg: float = 45.0
    travel_angle_deg: float = 10.0
    direction: WeldDirection = "up"
    weave: Weave = field(default_factory=Weave)
    crater_start_s: float = 0.0
    crater_end_s: float = 0.3
    passes: tuple[WeldPass, ...] = (WeldPass(),)

    @property
    def throat_mm(self) -> float:
        return self.leg_mm / 2.0**0.5
