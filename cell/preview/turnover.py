"""The planned turn of a two-sided job, before anything moves (``cell preview``, docs/flip.md): a top view and a
side view of the part as it lies for side A and at its nominal turned pose for side B, with the seams of each side
drawn in their side's colour and the seams no turn exposes in grey. Values only (the job's record)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from cell.preview.figures import new_figure, save_figure
from cell.types import WeldMap

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from cell.pipeline.turnover_run import TurnoverRun

SIDE_COLOURS = {"A": "tab:blue", "B": "tab:orange", "left": "0.55"}


def _draw(ax: Axes, weldmap: WeldMap, colour_of: dict[str, str], axes: tuple[int, int]) -> None:
    i, j = axes
    for part in weldmap.parts:  # any body's feature edges (a box's twelve)
        for e in part.edges():
            ax.plot(e[:, i], e[:, j], color="0.3", lw=0.6)
    grey = SIDE_COLOURS["left"]
    for seam in sorted(weldmap.seams, key=lambda m: colour_of.get(m.id) != grey):  # a side's seams over the grey
        colour = colour_of.get(seam.id)
        if colour is None:
            continue
        ax.plot([seam.p_start[i], seam.p_end[i]], [seam.p_start[j], seam.p_end[j]], color=colour, lw=2.2)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{'xyz'[i]}_R [m]")
    ax.set_ylabel(f"{'xyz'[j]}_R [m]")


def write_turnover(run: TurnoverRun, out_dir: Path) -> list[Path]:
    """``flip.png`` in ``out_dir``: side A's part and seams, the turn and side B's seams at the nominal turned
    pose; nothing when no turn was planned."""
    plan, turned = run.plan, run.turned_map
    if plan is None or turned is None:
        return []
    det = run.side_a.detection
    side = run.side_of()
    done_a = {s.id for s in run.side_a.seams if s.planned}
    exposed = set(plan.exposed)
    colour_a = {sid: SIDE_COLOURS["A"] for sid in done_a}
    colour_a |= {sid: SIDE_COLOURS["left"] for sid in side if sid not in done_a}
    colour_b = {sid: SIDE_COLOURS["B"] for sid in exposed} | {sid: SIDE_COLOURS["left"] for sid in plan.left}
    fig = new_figure(11.0, 7.0)
    axs = np.asarray(fig.subplots(2, 2)).reshape(2, 2)
    for col, (title, wm, colours) in enumerate(
        (("side A: as it lies", det.weldmap_R, colour_a), ("side B: turned (nominal)", turned, colour_b))
    ):
        _draw(axs[0, col], wm, colours, (0, 1))
        axs[0, col].set_title(f"{title}, top view", fontsize=9)
        _draw(axs[1, col], wm, colours, (1, 2))
        axs[1, col].set_title(f"{title}, side view", fontsize=9)
    verdict = "turn planned" if plan.go else f"no turn: {plan.reason}"
    fig.suptitle(
        f"{det.scenario.name}: {verdict} · {math.degrees(plan.angle_rad):+.0f} deg about the part's {plan.axis} "
        f"axis, lean {math.degrees(plan.tilt_rad):.1f} deg · side B seams {len(exposed)}, left {len(plan.left)}",
        fontsize=9,
    )
    out = Path(out_dir) / "flip.png"
    save_figure(fig, out)
    return [out]
