"""Which curved seams a re-scan looks at again: the doubtful ones (``cell weld``'s mode ``low``), every located one
(``all``), or those asked for by id (``cell rescan --seams``); every curve left says why."""

from __future__ import annotations

from collections.abc import Sequence

from cell.pipeline.records import Detection
from cell.pipeline.rescan import RescanMode
from cell.types import Reason, SeamStatus
from cell.types.curve_estimate import CurveEstimate


def doubtful_curves(det: Detection) -> list[CurveEstimate]:
    """The found curves whose worst sample's bound is over the weld tolerance (``rescan.max_sigma_m``): those a
    close-up may bring within it; and those not found for a surface no fixed camera sees (``no_support``)."""
    limit = det.scenario.rescan.max_sigma_m
    return [
        c
        for c in det.curve_estimates
        if (c.status is SeamStatus.FOUND and c.sigma_max_m > limit)
        or (c.status is SeamStatus.NOT_FOUND and c.code is Reason.NO_SUPPORT)
    ]


def chosen_curves(
    det: Detection, mode: RescanMode, curve_ids: Sequence[str] | None = None
) -> tuple[list[CurveEstimate], dict[str, str]]:
    """The curved seams to re-scan, in map order, and those left (id -> why). ``curve_ids``: those asked for, but
    one never searched (no two parts hold it, another method); else mode ``low``: :func:`doubtful_curves` (``cell
    weld``'s choice); ``all``: every located curve and those :func:`doubtful_curves` looks for where the map draws
    them."""
    limit = det.scenario.rescan.max_sigma_m
    doubtful = {c.id for c in doubtful_curves(det)}
    chosen: list[CurveEstimate] = []
    left: dict[str, str] = {}
    for c in det.curve_estimates:
        if c.status is SeamStatus.NOT_SUPPORTED:
            left[c.id] = f"not re-scanned: never searched ({c.reason})"
        elif curve_ids is not None:
            if c.id in curve_ids:
                chosen.append(c)
            else:
                left[c.id] = "not re-scanned: not among --seams"
        elif c.id in doubtful or (mode == "all" and c.status is SeamStatus.FOUND):
            chosen.append(c)
        elif c.status is SeamStatus.FOUND:
            left[c.id] = (
                f"not re-scanned: sigma up to {c.sigma_max_m * 1000:.3f} mm, within the {limit * 1000:.3f} mm the"
                " weld tolerance allows (--all looks again)"
            )
        else:
            left[c.id] = f"not re-scanned: not located ({c.reason}); --seams {c.id} looks for it where the map draws it"
    return chosen, left
