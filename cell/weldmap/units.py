"""Drawing units: what ``$INSUNITS`` declares, what the caller says, and which one wins (no ezdxf here)."""

from __future__ import annotations

import math

from cell.errors import MapUnitsError

UNITS_BY_INSUNITS = {1: "in", 4: "mm", 5: "cm", 6: "m"}
METRES_PER_UNIT = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "in": 0.0254}
NAMES = {"mm": "millimetres", "cm": "centimetres", "m": "metres", "in": "inches"}
PLAUSIBLE_EXTENT_M = (0.1, 20.0)  # a robot-welded assembly across its map, smallest and largest [m]


def _how(source: str, unit: str = "mm") -> str:
    return f"`cell map info {source} --units {unit}` (or the scenario key map.units)"


def resolve_units(code: int, override: str | None, source: str) -> tuple[str, list[str]]:
    """The units to read the drawing in and the warnings to give.

    code : the drawing's ``$INSUNITS`` (0: none declared). override : the caller's units (``--units`` /
    ``map.units``), which win over a declared code, with a warning when the two disagree.
    Raises MapUnitsError when neither gives usable units.
    """
    valid = ", ".join(METRES_PER_UNIT)
    if override is not None and override not in METRES_PER_UNIT:
        raise MapUnitsError(f"unknown map units {override!r} (--units or the scenario key map.units); valid: {valid}")
    declared = UNITS_BY_INSUNITS.get(code)
    if override is not None:
        if code == 0 or declared == override:
            return override, []
        what = f"{declared}" if declared else "units this reader does not know"
        return override, [f"{source}: the drawing declares $INSUNITS={code} ({what}); read in {override} as asked"]
    if declared is not None:
        return declared, []
    if code != 0:
        raise MapUnitsError(
            f"{source}: $INSUNITS={code} is not supported (supported: 1 in, 4 mm, 5 cm, 6 m); "
            f"say which units it is drawn in: {_how(source)}"
        )
    raise MapUnitsError(
        f"{source}: the drawing declares no units ($INSUNITS missing or 0); "
        f"say which units it is drawn in: {_how(source)}, one of {valid}"
    )


def extent_warning(extent_units: float, unit: str, source: str) -> str | None:
    """A warning when the map's size in ``unit`` is no welded part's (units declared wrong?), naming better units."""
    extent_m = extent_units * METRES_PER_UNIT[unit]
    lo, hi = PLAUSIBLE_EXTENT_M
    if lo <= extent_m <= hi or extent_units <= 0.0:
        return None
    fits = [u for u, k in METRES_PER_UNIT.items() if lo <= extent_units * k <= hi]
    if not fits:
        return (
            f"{source}: read in {NAMES[unit]}, the map is {extent_m:.3g} m across, no welded part's size in any units"
        )
    best = min(fits, key=lambda u: abs(math.log(extent_units * METRES_PER_UNIT[u])))
    return (
        f"{source}: read in {NAMES[unit]}, the map is only {extent_m * 1000:.3g} mm across"
        if extent_m < lo
        else f"{source}: read in {NAMES[unit]}, the map is {extent_m:.3g} m across"
    ) + (
        f"; if it is drawn in {NAMES[best]} ({extent_units * METRES_PER_UNIT[best] * 1000:.0f} mm across), "
        f"read it with {_how(source, best)}"
    )
