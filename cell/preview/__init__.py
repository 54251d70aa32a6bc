"""Pictures of a run that a person would rather look at than read: PNGs (matplotlib, Agg), one HTML page (plotly) and
a Rerun recording, drawn from plain values in the robot frame R [m, rad] in millimetres and degrees (docs/cli.md,
"Pictures and recordings"). The plotting libraries are imported inside the functions: importing this costs nothing."""

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
