"""A picture of the proposed seams with their ids, for the review of a map made from CAD (matplotlib, Agg): a
perspective view, a top view with the seams numbered and their list (id, shape, length, joint, dihedral,
status), parts grey, fasteners and fixtures blue, proposals red (curved ones dashed),
rejected ones grey and dotted. Millimetres, frame ``M``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from cell.cad.proposals import Proposal, Proposals, summary_rows
from cell.cad.roles import Role
from cell.geometry import FloatArray

MM = 1000.0
PART_COLOUR, FIXTURE_COLOUR = "0.45", "tab:blue"
PROPOSED_COLOUR, REJECTED_COLOUR = "red", "0.6"


def _curve(p: Proposal) -> FloatArray:
    return np.asarray(p.curve.at(np.linspace(0.0, 1.0, 3 if p.curve.kind == "line" else 64)) * MM)


def _draw(ax: Any, found: Proposals, ij: tuple[int, int] | None) -> None:
    def plot(pts: FloatArray, **kw: Any) -> None:
        if ij is None:
            ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], **kw)
        else:
            ax.plot(pts[:, ij[0]], pts[:, ij[1]], **kw)

    centre = {}
    for body, role in zip(found.model.bodies, found.roles, strict=True):
        colour = PART_COLOUR if role == Role.PART else FIXTURE_COLOUR
        centre[body.name] = body.vertices.mean(axis=0) * MM
        for e in body.edges:
            plot(e.at(np.linspace(0.0, 1.0, 2 if e.kind == "line" else 48)) * MM, color=colour, lw=0.5)
    for k, s in enumerate(found.seams):
        pts = _curve(s)
        proposed = s.rejected is None
        if proposed:
            plot(pts, color=PROPOSED_COLOUR, lw=2.2, ls="--" if s.curved else "-")
        else:
            plot(pts, color=REJECTED_COLOUR, lw=1.2, ls=":")
        if ij is None:
            continue  # the numbers go on the top view, where the parts hide none of them
        at = pts[len(pts) // 2] if len(pts) == 3 else pts[(11 * k) % len(pts)]  # concentric circles' apart
        away = (at - centre[s.abutting])[list(ij)]  # the number outside the abutting part
        away = away / max(float(np.linalg.norm(away)), 1e-9) * 9.0
        ax.annotate(
            str(k + 1),
            (at[ij[0]], at[ij[1]]),
            xytext=(away[0], away[1]),
            textcoords="offset points",
            fontsize=7 if proposed else 5,
            color=PROPOSED_COLOUR if proposed else REJECTED_COLOUR,
            ha="center",
            va="center",
            fontweight="bold" if proposed else "normal",
        )


def _listing(ax: Any, found: Proposals) -> None:
    """The seams by number: id, shape and length, joint and dihedral, or why rejected."""
    ax.set_axis_off()
    rows = summary_rows(found)
    size = 7.0 if len(rows) <= 30 else 5.0
    step = min(0.045, 0.95 / max(len(rows), 1))
    for k, (row, s) in enumerate(zip(rows, found.seams, strict=True)):
        seam_id, shape, length, joint, deg, status = row
        text = f"{k + 1:>2}  {seam_id}  {shape} {length} mm  {joint} {deg} deg  {status}"
        colour = PROPOSED_COLOUR if s.rejected is None else REJECTED_COLOUR
        ax.text(0.0, 0.97 - k * step, text, fontsize=size, color=colour, family="monospace", va="top")


def draw_proposals(found: Proposals, path: str | Path) -> Path:
    """Write the picture of the proposals to ``path`` (PNG); returns it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    fig = Figure(figsize=(18.0, 6.5), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(1, 3, width_ratios=(1.0, 1.0, 0.9))
    ax3 = fig.add_subplot(grid[0, 0], projection="3d")
    _draw(ax3, found, None)
    all_v = np.concatenate([b.vertices for b in found.model.bodies]) * MM
    lo, hi = all_v.min(axis=0), all_v.max(axis=0)
    ax3.set_box_aspect(tuple(np.maximum(hi - lo, 1e-3 * float(np.ptp(all_v)))))
    ax3.view_init(elev=30.0, azim=-60.0)
    ax3.set_xlabel("x [mm]", fontsize=8)
    ax3.set_ylabel("y [mm]", fontsize=8)
    ax3.set_zlabel("z [mm]", fontsize=8)
    ax3.tick_params(labelsize=6)
    top = fig.add_subplot(grid[0, 1])
    _draw(top, found, (0, 1))
    top.set_aspect("equal")
    top.set_xlabel("x [mm]", fontsize=8)
    top.set_ylabel("y [mm]", fontsize=8)
    top.tick_params(labelsize=7)
    top.set_title("top view, seams by number", fontsize=9)
    listing = fig.add_subplot(grid[0, 2])
    _listing(listing, found)
    n_prop, n_rej = len(found.proposed), len(found.seams) - len(found.proposed)
    fig.suptitle(f"{Path(found.model.source).name}: {n_prop} seams proposed, {n_rej} rejected", fontsize=10)
    handles = [
        Line2D([], [], color=PROPOSED_COLOUR, lw=2.2, label="proposed (WELD_SEAMS)"),
        Line2D([], [], color=PROPOSED_COLOUR, lw=2.2, ls="--", label="proposed, curved"),
        Line2D([], [], color=REJECTED_COLOUR, lw=1.2, ls=":", label="rejected (WELD_REJECTED)"),
        Line2D([], [], color=PART_COLOUR, lw=0.8, label="part"),
        Line2D([], [], color=FIXTURE_COLOUR, lw=0.8, label="fastener or fixture"),
    ]
    listing.legend(handles=handles, fontsize=7, loc="lower left")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    return path
