"""One page to look at: a run's results table, its 3D cell and its joint plots in one self-contained HTML file.

plotly.js is inlined once (the page opens offline); the cloud is thinned so that fence1's page stays a few
megabytes. Values only: the run's records and the values it carries (:class:`~cell.types.CellView`).
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from cell.geometry import FloatArray, invert, transform_points
from cell.outputs import write_text
from cell.preview.curves3d import curve_traces
from cell.preview.html import figure_3d
from cell.preview.results import results_rows, results_table
from cell.preview.views import ARC_COLOUR, STATUS_COLOURS, SeamView, seam_views
from cell.types import JointLimits, SeamRecord, Trajectory, WeldPlan
from cell.types.run import WeldReason, partial_text

if TYPE_CHECKING:
    from cell.pipeline.records import WeldRun

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 1em 2em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.1em; margin-top: 1.5em; }
table#results { border-collapse: collapse; font-size: 0.9em; }
#results th, #results td { border-bottom: 1px solid #ddd; padding: 0.25em 0.8em; text-align: right; }
#results th:first-child, #results td:first-child { text-align: left; }
#results tr:hover { background: #f4f4f4; }
.note { color: #666; font-size: 0.85em; }
"""
_JOINT_SAMPLES = 1500  # samples of the 1 kHz trajectory drawn in the joint plots


def arc_bands(plan: WeldPlan) -> list[tuple[float, float, str]]:
    """(start, end [s], seam id) of every weld of the plan, in plan time."""
    return [(s.t0, s.t1, s.seam_id) for s in plan.segments if s.arc_on]


def joint_figure(traj: Trajectory, limits: JointLimits, bands: Sequence[tuple[float, float, str]]) -> Any:
    """Joint positions [deg] over time, one row per joint, with the limits as red lines (the axis fits the
    motion, so a limit far away is named in the row title) and the arc-on bands shaded and labelled by seam."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    k = max(1, len(traj.times) // _JOINT_SAMPLES)
    t, q = traj.times[::k], np.degrees(traj.q[::k])
    lo, hi = np.degrees(limits.q_min), np.degrees(limits.q_max)
    titles = [f"{n} (limits {a:.0f} .. {b:.0f} deg)" for n, a, b in zip(limits.names, lo, hi, strict=True)]
    fig = make_subplots(rows=limits.dof, cols=1, shared_xaxes=True, subplot_titles=titles, vertical_spacing=0.03)
    # The limits, bands and labels are laid out at once: plotly's add_hline / add_vrect validate the whole layout
    # at each call (seconds for a job of many welds).
    shapes: list[dict[str, Any]] = []
    labels: list[dict[str, Any]] = []
    for j in range(limits.dof):
        row = j + 1
        fig.add_trace(
            go.Scatter(x=t, y=q[:, j], mode="lines", name=limits.names[j], line={"color": "#1f77b4"}), row=row, col=1
        )
        axes = fig.get_subplot(row, 1)
        x, y = axes.xaxis.plotly_name.replace("axis", ""), axes.yaxis.plotly_name.replace("axis", "")
        span = max(float(np.ptp(q[:, j])), 5.0)
        ylo, yhi = float(q[:, j].min()) - 0.15 * span, float(q[:, j].max()) + 0.15 * span
        shapes += [
            {"type": "line", "xref": f"{x} domain", "x0": 0, "x1": 1, "yref": y, "y0": float(limit),
             "y1": float(limit), "line": {"color": "#d62728", "dash": "dash", "width": 1}}
            for limit in (lo[j], hi[j]) if ylo <= limit <= yhi
        ]  # fmt: skip
        fig.update_yaxes(range=[ylo, yhi], title_text="[deg]", row=row, col=1)
        for a, b, seam in bands:
            shapes.append({"type": "rect", "xref": x, "x0": a, "x1": b, "yref": f"{y} domain", "y0": 0, "y1": 1,
                           "fillcolor": ARC_COLOUR, "opacity": 0.35, "line": {"width": 0}})  # fmt: skip
            if j == 0:
                labels.append({"x": (a + b) / 2.0, "xref": x, "y": 1.0, "yref": f"{y} domain", "text": seam,
                               "showarrow": False, "textangle": -90, "yanchor": "bottom",
                               "font": {"size": 9}})  # fmt: skip
    fig.update_layout(shapes=shapes, annotations=[*fig.layout.annotations, *labels])
    fig.update_xaxes(title_text="time [s]", row=limits.dof, col=1)
    fig.update_layout(
        height=170 * limits.dof + 160,
        showlegend=False,
        margin={"l": 60, "r": 20, "t": 120, "b": 40},
        title={"text": "joint positions: limits dashed red, arc on shaded (labelled by seam)"},
    )
    return fig


def draw_inputs(run: WeldRun) -> tuple[FloatArray, list[SeamView], dict[str, FloatArray], dict[str, FloatArray]]:
    """What the pictures of a run draw, in R [m]: the dense cloud ((0, 3) when perception failed), the seams,
    the planned torch poses by seam, and the tool paths: the executed one (arc on) when the arm moved, else the
    planned torch positions by seam."""
    det = run.detection
    cloud = det.scene.perceived.dense.points if det.scene is not None else np.zeros((0, 3))
    poses = {sid: np.asarray(X) for sid, X in run.torch_paths.items()}
    if run.execution is not None:
        ex = run.execution
        tcp = {"executed": transform_points(invert(det.scenario.X_WR), ex.tcp_W[ex.arc_on])}
    else:
        tcp = {sid: X[:, :3, 3] for sid, X in poses.items()}
    return np.asarray(cloud, dtype=float), seam_views(run.records()), poses, tcp


def _summary(run: WeldRun, records: Sequence[SeamRecord]) -> str:
    det = run.detection
    curves = det.curve_welds.values()  # a weld run's curved seams
    welded = sum(1 for r in records if r.weld is not None and r.weld.welded) + sum(w.welded for w in curves)
    planned = sum(1 for r in records if r.weld is not None and r.weld.planned) + sum(w.planned for w in curves)
    codes = [str(u.code) for u in det.not_welded if u.id not in det.curve_welds]
    part = [w for w in curves if w.code is WeldReason.PARTIAL]  # welded in part, the rest for a manual weld
    tried = [str(u.code) for u in det.not_welded if u.id in det.curve_welds and str(u.code) != WeldReason.PARTIAL]
    parts = [f"{len(det.estimates) + len(det.weldmap_R.not_straight)} seams in the map", f"{planned} planned"]
    parts.append(f"{welded} welded")
    if codes:
        parts.append(f"{len(codes)} not supported: {', '.join(sorted(set(codes)))}")
    if part:
        parts.append(partial_text(len(part), sum(w.manual_m for w in part) * 1000.0))
    if tried:
        parts.append(f"{len(tried)} curved not welded: {', '.join(sorted(set(tried)))}")
    if run.execution is not None:
        parts.append(f"cycle time {run.cycle_time_s:.1f} s")
    if det.lost_cameras:
        parts.append(f"cameras lost: {', '.join(det.lost_cameras)}")
    text = " · ".join(parts)
    if run.error is not None:
        text += f"<br><b>error</b>: {html.escape(run.error.message)}"
    return text


def write_page(run: WeldRun, out_path: str | Path, *, title: str = "", max_points: int = 30_000) -> Path:
    """The run's page (module docstring): results table, 3D view (cloud, aligned map, seams by status, table,
    robot along its path, camera frusta), joint plots. Without a cloud (perception failed) the 3D view shows
    the cell only. Returns ``out_path``."""
    det = run.detection
    records = run.records()
    title = title or f"{det.scenario.name} · {det.method} · {det.scenario.noise} noise"
    hover = {
        r["seam"]: f"{r['status'].replace('_', ' ')} · sigma {r['sigma [mm]']} mm · error {r['error [mm]']} mm"
        f" · {r['weld']}<br>{html.escape(r['detail'])}"
        for r in results_rows(records)
    }
    cloud, views, poses, tcp = draw_inputs(run)
    X_MR = invert(det.scene.X_RM) if det.scene is not None else None
    curves = curve_traces(det.curve_estimates, det.curve_welds, X_MR)
    fig3d = figure_3d(
        cloud, det.weldmap_R, views, poses, tcp, title=title, max_points=max_points, view=run.view, hover=hover,
        extra=curves,
    )  # fmt: skip
    body = [
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{_summary(run, records)}</p>",
        "<h2>Seams</h2>",
        results_table(
            records, STATUS_COLOURS, [u for u in det.not_welded if u.id not in det.curve_welds], det.curve_welds
        ),
        '<p class="note">sigma: the locator\'s standard error across the seam; error: mean distance of the estimate'
        " from the true seam (when the truth is known); angles: the torch's work and travel angles as planned.</p>",
        "<h2>The cell</h2>",
        fig3d.to_html(full_html=False, include_plotlyjs=True, div_id="cell3d", default_height="80vh"),
    ]
    limits = run.view.limits if run.view is not None else None
    if run.plan is not None and run.plan.segments and limits is not None:
        traj, _ = run.plan.joint_trajectory()
        jf = joint_figure(traj, limits, arc_bands(run.plan))
        body += ["<h2>Joints</h2>", jf.to_html(full_html=False, include_plotlyjs=False, div_id="joints")]
    page = (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
        f"<style>{_STYLE}</style></head><body>\n" + "\n".join(body) + "\n</body></html>\n"
    )
    return write_text(out_path, page, what="page")
