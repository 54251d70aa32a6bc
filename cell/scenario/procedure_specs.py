"""Weld procedures in a scenario: the WPS table (``procedures:``, or ``procedures_file:`` beside the scenario)
validated row by row into :class:`cell.types.WeldProcedure` values, in a WPS's units; with no table, one row made
from ``process:`` (:func:`default_procedure`) applies to every seam."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, model_validator

from cell.errors import ScenarioError
from cell.scenario.base import Model, NonNeg
from cell.scenario.yaml_text import parse
from cell.types.procedure import Weave, WeldPass, WeldProcedure


class WeaveSpec(Model):
    """Oscillation of the torch while it travels on along the seam (:mod:`cell.process.weave`): ``zigzag``
    side to side across the bisector with smooth turns, fading in and out over the first and last wavelength;
    ``triangle`` side to side on straight legs with sharp turns, at full width from the start (ArcTech's
    #Triangle); ``circle`` round a circle of the width's diameter in the joint's cross-section, from the pass line
    out of the root and back, at a constant angular speed (no dwells; the first and last turns eased in and out
    from rest). ``width_mm`` peak to peak,
    ``frequency_hz`` full cycles per second, ``dwell_s`` [left (face A side), right] at the sides (their sum below
    80 % of one period)."""

    pattern: Literal["none", "zigzag", "triangle", "circle"] = "none"  # none: a straight bead
    width_mm: Annotated[float, Field(ge=0.0, le=30.0)] = 0.0
    frequency_hz: Annotated[float, Field(ge=0.0, le=10.0)] = 0.0  # side-to-side-and-back cycles per second
    dwell_s: tuple[NonNeg, NonNeg] = (0.0, 0.0)

    @model_validator(mode="after")
    def _fits(self) -> WeaveSpec:
        if self.pattern != "none":
            if self.width_mm <= 0.0 or self.frequency_hz <= 0.0:
                raise ValueError(f"a {self.pattern} weave needs width_mm > 0 and frequency_hz > 0")
            period = 1.0 / self.frequency_hz
            if self.pattern == "circle" and sum(self.dwell_s) > 0.0:
                raise ValueError(
                    "a circle weave takes no dwells (dwell_s [0, 0]): its TCP circles at a constant angular speed; "
                    "for dwells at the sides use zigzag or triangle"
                )
            if sum(self.dwell_s) >= 0.8 * period:
                raise ValueError(
                    f"weave dwells {self.dwell_s[0]:g} + {self.dwell_s[1]:g} s leave no time to cross in one period "
                    f"of {period:.3g} s (at most 80 % of it)"
                )
        return self

    def to_weave(self) -> Weave:
        return Weave(self.pattern, self.width_mm, self.frequency_hz, (self.dwell_s[0], self.dwell_s[1]))


class PassSpec(Model):
    """One pass: offset from the root in the joint's cross-section [mm] (``lateral_mm`` across the bisector,
    towards face A positive; ``lift_mm`` along the bisector, out of the root) and its travel speed (0: the
    procedure's)."""

    lateral_mm: Annotated[float, Field(ge=-20.0, le=20.0)] = 0.0
    lift_mm: Annotated[float, Field(ge=0.0, le=20.0)] = 0.0
    travel_speed_mm_s: Annotated[float, Field(ge=0.0, le=100.0)] = 0.0

    def to_pass(self) -> WeldPass:
        return WeldPass(self.lateral_mm, self.lift_mm, self.travel_speed_mm_s)


class ProcedureSpec(Model):
    """One WPS row: where it applies (``joint`` T | corner | lap | any, ``position`` PA | PB | PF | PG | any,
    seam leg ``leg_min_mm``..``leg_max_mm``), the arc, the torch, the weave, the craters and the passes. Torch
    angles default to ``process:``'s; ``direction`` (up | down | as_drawn) applies to vertical seams."""

    name: Annotated[str, Field(min_length=1)]  # the row's name (reports, weld data sets)
    joint: Literal["T", "corner", "lap", "any"] = "any"  # joint type it applies to (from the map)
    position: Literal["PA", "PB", "PF", "PG", "any"] = "any"  # ISO 6947 welding position it applies to
    leg_min_mm: NonNeg = 0.0  # the seam legs (process.leg_mm) it applies to, from
    leg_max_mm: NonNeg = 1000.0  # to
    process: str = "135 MAG"  # ISO 4063 process number and name
    wire: str = "ISO 14341-A G3Si1, 1.0 mm"  # filler wire: classification and diameter
    gas: str = "ISO 14175 M21 (Ar + 18 % CO2), 15 l/min"  # shielding gas and flow
    current_a: Annotated[float, Field(gt=0.0, le=600.0)] = 190.0  # welding current [A]
    voltage_v: Annotated[float, Field(gt=0.0, le=50.0)] = 21.5  # arc voltage [V]
    wire_feed_m_min: Annotated[float, Field(gt=0.0, le=30.0)] = 7.0  # wire feed speed [m/min]
    travel_speed_mm_s: Annotated[float, Field(gt=0.0, le=100.0)] = 8.0  # along the seam
    leg_mm: Annotated[float, Field(gt=0.0, le=30.0)] = 4.0  # the fillet leg it lays (throat = leg / sqrt 2)
    work_angle_deg: Annotated[float, Field(gt=0.0, lt=90.0)] | None = None  # None: process.work_angle_deg
    travel_angle_deg: Annotated[float, Field(ge=-45.0, le=45.0)] | None = None  # None: process.travel_angle_deg
    direction: Literal["up", "down", "as_drawn"] = "up"  # of a seam within 30 deg of vertical
    weave: WeaveSpec = WeaveSpec()
    crater_start_s: Annotated[float, Field(ge=0.0, le=5.0)] = 0.0  # hot start at the weld start, at rest
    crater_end_s: Annotated[float, Field(ge=0.0, le=5.0)] = 0.3  # crater fill at the weld end, at rest
    passes: Annotated[tuple[PassSpec, ...], Field(min_length=1, max_length=20)] = (PassSpec(),)

    @model_validator(mode="after")
    def _legs(self) -> ProcedureSpec:
        if self.leg_min_mm > self.leg_max_mm:
            raise ValueError(f"leg_min_mm {self.leg_min_mm:g} > leg_max_mm {self.leg_max_mm:g}")
        return self

    def to_procedure(self, work_angle_deg: float, travel_angle_deg: float) -> WeldProcedure:
        """The value the planner uses; the torch angles not given here are the process's (arguments, [deg])."""
        return WeldProcedure(
            name=self.name,
            joint=self.joint,
            position=self.position,
            leg_min_mm=self.leg_min_mm,
            leg_max_mm=self.leg_max_mm,
            process=self.process,
            wire=self.wire,
            gas=self.gas,
            current_a=self.current_a,
            voltage_v=self.voltage_v,
            wire_feed_m_min=self.wire_feed_m_min,
            travel_speed_mm_s=self.travel_speed_mm_s,
            leg_mm=self.leg_mm,
            work_angle_deg=work_angle_deg if self.work_angle_deg is None else self.work_angle_deg,
            travel_angle_deg=travel_angle_deg if self.travel_angle_deg is None else self.travel_angle_deg,
            direction=self.direction,
            weave=self.weave.to_weave(),
            crater_start_s=self.crater_start_s,
            crater_end_s=self.crater_end_s,
            passes=tuple(p.to_pass() for p in self.passes),
        )


def default_procedure(travel_speed_mm_s: float, work_angle_deg: float, travel_angle_deg: float) -> WeldProcedure:
    """The one procedure of a scenario without a WPS table: ``process:``'s speed and angles, any joint, any
    position, one pass, no weave, vertical seams welded upwards."""
    return WeldProcedure(
        name="process",
        travel_speed_mm_s=travel_speed_mm_s,
        work_angle_deg=work_angle_deg,
        travel_angle_deg=travel_angle_deg,
        direction="up",
    )


def with_procedures_file(data: dict[str, Any], base_dir: Path, source: str) -> dict[str, Any]:
    """The scenario mapping with ``procedures_file`` (a YAML list of rows, or a mapping with a ``procedures``
    list, resolved beside the scenario) read into ``procedures``; ScenarioError when the file is missing or not
    such a list, or when the scenario gives both keys."""
    name = data.get("procedures_file")
    if name is None:
        return data
    if not isinstance(name, str):
        raise ScenarioError(f"{source}: procedures_file must be a file name, got {name!r}")
    if "procedures" in data:
        raise ScenarioError(f"{source}: give procedures or procedures_file, not both")
    path = (base_dir / name).resolve()
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ScenarioError(f"{source}: procedures_file {name!r} cannot be read ({path}): {err}") from None
    rows = parse(text, f"{source}: procedures_file {name!r}")  # a key twice is refused here too
    if isinstance(rows, dict) and set(rows) == {"procedures"}:
        rows = rows["procedures"]
    if not isinstance(rows, list):
        raise ScenarioError(f"{source}: procedures_file {name!r} must hold a list of procedures (WPS rows)")
    return {**data, "procedures": rows}
