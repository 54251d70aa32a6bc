"""The welding order's transfers screened before they are searched in full: a transfer between two seams is first
asked between their planned lines only (the full approach and depart), every strategy once; one that no strategy
makes there is taken out of the order at that cost, a seventh of the full search over every pair of line lengths
(docs/positioner.md, "Planning time"). Only where the order search meets many transfers that no way makes (seams
in the openings of a part stood up on a positioner). Frames: R [m]; joints [rad]."""

from __future__ import annotations

import itertools
from collections.abc import Collection, Mapping, Sequence

from cell.geometry import FloatArray
from cell.planning.access.home import home_end
from cell.planning.short_lines import SeamLines
from cell.planning.transfers import TransferFail, Transfers


def first_unjoined(
    transfers: Transfers,
    ordered: Sequence[str],
    lines: Mapping[str, SeamLines],
    q_home: FloatArray,
    skip: Collection[tuple[str, str]] = (),
) -> tuple[str, str, TransferFail] | None:
    """The first transfer of the welding order (home, the seams ``ordered``, home; "" = home), but those in
    ``skip``, that no strategy makes between the planned lines, as (from id, to id, why: the full search's own
    failure there); None when every one is made. A transfer made there is made by the full search too (it tries
    that pair among the others); one refused there may still be made between shorter lines: the full search is
    asked when no order avoids it (``skip``: the transfers already refused)."""
    home = home_end(q_home)[0]
    for a, b in itertools.pairwise(["", *ordered, ""]):
        if (a, b) in skip:
            continue
        out = lines[a].exits[-1] if a else home
        into = lines[b].entries[-1] if b else home
        got = transfers.between([out.q], [into.q])
        if isinstance(got, TransferFail):
            return a, b, got
    return None
