"""A seam the arm can neither reach from home nor leave for home: every transfer strategy (direct, hops, lifts,
via home, the ways out of an opening) meets something at every line length, both ways. Where another place may
hold the seam (a positioner's other poses), the planner refuses it at once rather than trying every other seam's
transfer to it in every order (docs/positioner.md, "Planning time"). Frames: R [m]; joints [rad]."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from cell.geometry import FloatArray
from cell.planning.short_lines import LineEnd, SeamLines, join
from cell.planning.transfers import TransferFail, Transfers


def home_end(q_home: FloatArray) -> tuple[LineEnd, ...]:
    """Home as the end of a transfer (the planner's assembly meets it the same way)."""
    return (LineEnd("move", np.asarray(q_home)[None, :], 0.0, np.zeros(3), np.eye(4), True),)


def cut_off(transfers: Transfers, lines: SeamLines, q_home: FloatArray) -> TransferFail | None:
    """Why no transfer joins the seam to home either way (the way in from home's failure), or None when one does.
    Each way is asked between the planned line and home first (:func:`planned_way`), then over every line length;
    the searches are the transfers' own, remembered: the plan asks the same ones again for free."""
    home = home_end(q_home)
    if planned_way(transfers, home[0], lines.entries[-1]):
        return None
    way_in = join(transfers, home, lines.entries)
    if not isinstance(way_in, TransferFail):
        return None
    if planned_way(transfers, lines.exits[-1], home[0]):
        return None
    way_out = join(transfers, lines.exits, home)
    return way_in if isinstance(way_out, TransferFail) else None


def planned_way(transfers: Transfers, out: LineEnd, into: LineEnd) -> bool:
    """Whether a strategy makes the transfer between these two line ends (the planned lines, or home): enough to
    know that the search over every line length makes it too (it tries this pair among the others), at a seventh
    of its cost when it is made with shorter lines."""
    return not isinstance(transfers.between([out.q], [into.q]), TransferFail)


def first_cut_off(
    transfers: Transfers, lines: Mapping[str, SeamLines], q_home: FloatArray, ids: Iterable[str]
) -> tuple[str, TransferFail] | None:
    """The first seam of ``ids`` ("" = home, skipped) that :func:`cut_off` finds joined to home neither way, and why."""
    for sid in ids:
        if sid:
            why = cut_off(transfers, lines[sid], q_home)
            if why is not None:
                return sid, why
    return None
