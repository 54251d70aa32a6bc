"""Pictures of a run that a person would rather look at than read: PNGs (matplotlib, Agg) and one HTML (plotly).

Everything here takes plain values (arrays, a :class:`~cell.types.WeldMap`, seam tuples) in the robot frame R
[m, rad] and draws in millimetres and degrees. matplotlib and plotly are imported inside the functions, so
importing this package costs nothing.

- :mod:`cell.preview.views`: what is drawn (colours, seams as lines, thinned cloud, box edges, torch glyphs).
- :mod:`cell.preview.figures`: the overview PNGs (top view, perspective, one close-up per seam).
- :mod:`cell.preview.labels`: seam labels that do not overlap.
- :mod:`cell.preview.joint_plots`: the joint plot PNG (positions and velocities against the limits).
- :mod:`cell.preview.html`: the interactive 3D view (plotly): cloud, map, seams, and with the run's
  :class:`~cell.types.CellView` the table, the robot (:mod:`cell.preview.solids`, :mod:`cell.preview.cell3d`) and
  the cameras, framed to the part.
- :mod:`cell.preview.results`: the results table (one row per seam).
- :mod:`cell.preview.page`: :func:`write_page`, one self-contained HTML page of a run (results, 3D, joints).
- :mod:`cell.preview.run`: :func:`write_run`, every picture of a ``cell weld`` / ``cell preview`` run.
"""

from cell.preview.figures import render_overview
from cell.preview.html import render_html
from cell.preview.joint_plots import render_joint_plots
from cell.preview.page import write_page
from cell.preview.run import write_run
from cell.preview.views import (
    ARC_COLOUR,
    AXIS_COLOURS,
    BOX_COLOUR,
    MM,
    PATH_COLOUR,
    STATUS_COLOURS,
    TRUTH_COLOUR,
    SeamView,
    seam_views,
)

__all__ = [
    "ARC_COLOUR",
    "AXIS_COLOURS",
    "BOX_COLOUR",
    "MM",
    "PATH_COLOUR",
    "STATUS_COLOURS",
    "TRUTH_COLOUR",
    "SeamView",
    "render_html",
    "render_joint_plots",
    "render_overview",
    "seam_views",
    "write_page",
    "write_run",
]
