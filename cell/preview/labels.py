"""Seam labels on a matplotlib picture that do not overlap one another."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

_LABEL_OFFSETS = ((5, 5), (5, -14), (-5, 5), (-5, -14), (14, 16), (14, -26), (-14, 16), (-14, -26), (30, 0), (-30, 0))


def place_labels(fig: Figure, ax: Axes, labels: Sequence[tuple[str, tuple[float, float]]]) -> list[Any]:
    """Seam labels at their points (data coordinates of ``ax``), each moved to the first of a few offsets
    [points] where its box overlaps no label placed before it (the figure is laid out once to measure them).
    Returns the annotations."""
    anns = [
        ax.annotate(
            text, (x, y), xytext=_LABEL_OFFSETS[0], textcoords="offset points", fontsize=7, zorder=7,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8},
        )
        for text, (x, y) in labels
    ]  # fmt: skip
    for a in anns:
        a.set_in_layout(False)  # labels never move the axes
    if not anns:
        return anns
    fig.canvas.draw()  # the layout (constrained) is final only once drawn
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    placed: list[Any] = []
    for a in anns:
        for dx, dy in _LABEL_OFFSETS:
            a.set_position((dx, dy))
            a.set_horizontalalignment("left" if dx >= 0 else "right")
            a.set_verticalalignment("bottom" if dy >= 0 else "top")
            box = a.get_window_extent(renderer)
            if not any(box.overlaps(b) for b in placed):
                break
        placed.append(a.get_window_extent(renderer))
    return anns
