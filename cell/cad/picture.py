"""A picture of the proposed seams with their ids, for the review of a map made from CAD (matplotlib, Agg): a
perspective view and a top view, parts grey, fasteners and fixtures blue, proposals red (curved ones dashed),
rejected ones grey and dotted. Millimetres, frame ``M``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from cell.cad.proposals import Proposals
from cell.cad.roles import Role
from cell.geometry import FloatArray

MM = 1000.0
PART_COLOUR, FIXTURE_COLOUR = "0.45", "tab:blue"
PROPOSED_COLOUR, REJECTED_COLOUR = "red", "0.6"


def _curve(p: Any) -> FloatArray:
    return np.asarray(p.curve.at(np.linspace(0.0, 1.0, 2 if p.curve.kind == "line" else 64)) * MM)


def _draw(ax: Any, found: Proposals, ij: tuple[int, int] | None) -> None:
    def plot(pts: FloatArray, **kw: Any) -> None:
        if ij is None:
            ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], **kw)
        else:
            ax.plot(pts[:, ij[0]], pts[:, ij[1]], **kw)

    for body, role in zip(found.model.bodies, found.roles, strict=True):
        colour = PART_COLOUR if role == Role.PART else FIXTURE_COLOUR
        for e in body.edges:
            plot(e.at(np.linspace(0.0, 1.0, 2 if e.kind == "line" else 48)) * MM, color=colour, lw=0.5)
    for k, s in enumerate(found.seams):
        pts = _curve(s)
        if s.rejected is None:
            plot(pts, color=PROPOSED_COLOUR, lw=2.2, ls="--" if s.curved else "-")
        else:
            plot(pts, color=REJECTED_COLOUR, lw=1.2, ls=":")
        if ij is None:
            continue  # the ids go on the top view, where they do not hide one another behind the parts
        mid = pts[len(pts) // 2] if len(pts) == 2 else pts[(7 * k) % len(pts)]  # ids of concentric circles apart
        colour = PROPOSED_COLOUR if s.rejected is None else REJECTED_COLOUR
        ax.annotate(s.id, (mid[ij[0]], mid[ij[1]]), fontsize=6, color=colour, xytext=(3, 3), textcoords="offset points")


def draw_proposals(found: Proposals, path: str | Path) -> Path:
    """Write the picture of the proposals to ``path`` (PNG); returns it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    fig = Figure(figsize=(13.0, 6.0), dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    ax3 = fig.add_subplot(1, 2, 1, projection="3d")
    _draw(ax3, found, None)
    all_v = np.concatenate([b.vertices for b in found.model.bodies]) * MM
    lo, hi = all_v.min(axis=0), all_v.max(axis=0)
    ax3.set_box_aspect(tuple(np.maximum(hi - lo, 1e-3 * float(np.ptp(all_v)))))
    ax3.view_init(elev=30.0, azim=-60.0)
    ax3.set_xlabel("x [mm]", fontsize=8)
    ax3.set_ylabel("y [mm]", fontsize=8)
    ax3.set_zlabel("z [mm]", fontsize=8)
    ax3.tick_params(labelsize=6)
    top = fig.add_subplot(1, 2, 2)
    _draw(top, found, (0, 1))
    top.set_aspect("equal")
    top.set_xlabel("x [mm]", fontsize=8)
    top.set_ylabel("y [mm]", fontsize=8)
    top.tick_params(labelsize=7)
    top.set_title("top view, seam ids", fontsize=9)
    n_prop, n_rej = len(found.proposed), len(found.seams) - len(found.proposed)
    fig.suptitle(f"{Path(found.model.source).name}: {n_prop} seams proposed, {n_rej} rejected", fontsize=10)
    handles = [
        Line2D([], [], color=PROPOSED_COLOUR, lw=2.2, label="proposed (WELD_SEAMS)"),
        Line2D([], [], color=PROPOSED_COLOUR, lw=2.2, ls="--", label="proposed, curved (not welded yet)"),
        Line2D([], [], color=REJECTED_COLOUR, lw=1.2, ls=":", label="rejected (WELD_REJECTED)"),
        Line2D([], [], color=PART_COLOUR, lw=0.8, label="part"),
        Line2D([], [], color=FIXTURE_COLOUR, lw=0.8, label="fastener or fixture"),
    ]
    top.legend(handles=handles, fontsize=7, loc="best")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    return path
