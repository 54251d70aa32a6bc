"""Every picture of a ``cell weld`` / ``cell preview`` run, from the run's record."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from cell.errors import SensorError
from cell.preview.figures import render_overview
from cell.preview.joint_plots import render_joint_plots
from cell.preview.page import arc_bands, draw_inputs, write_page

if TYPE_CHECKING:
    from cell.pipeline.records import WeldRun


def write_run(run: WeldRun, out_dir: str | Path) -> list[Path]:
    """Every picture of a ``cell weld`` / ``cell preview`` run: overview PNGs, joint plots and the page
    ``cell.html`` (results table, 3D cell, joint plots: :func:`~cell.preview.page.write_page`).

    Tool paths are the executed ones when the arm moved, else the planned torch positions. When perception or
    alignment failed there is no cloud to draw: the detection's error is raised (a :class:`~cell.errors.CellError`).
    """
    det = run.detection
    if det.scene is None:
        raise det.error if det.error is not None else SensorError("nothing to draw: the run perceived no cloud")
    cloud, views, poses, tcp = draw_inputs(run)
    title = f"{det.scenario.name} · {det.method} · {det.scenario.noise} noise"
    out = Path(out_dir)
    paths = render_overview(cloud, det.weldmap_R, views, poses, tcp, out, title=title)
    limits = run.view.limits if run.view is not None else None
    if run.plan is not None and run.plan.segments and limits is not None:
        traj, arc = run.plan.joint_trajectory()
        k = max(1, len(traj.times) // 4000)  # 1 kHz samples: a few thousand are plenty for a plot
        paths.append(
            render_joint_plots(
                traj.times[::k],
                traj.q[::k],
                traj.qd[::k],
                limits,
                out / "joints.png",
                arc_on=arc[::k],
                title=title,
                bands=arc_bands(run.plan),
            )
        )
    paths.append(write_page(run, out / "cell.html", title=title))
    return paths
