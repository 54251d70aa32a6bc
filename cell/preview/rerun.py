"""A Rerun recording of a run (``cell weld --rerun FILE.rrd``, ``cell preview --rerun FILE.rrd``): the cell, the seams,
the cameras and the robot along the motion on one timeline (what it holds: docs/cli.md, "Pictures and
recordings"), from the run's values only (the motion: its view's :class:`~cell.types.view.ArmMotion`). The only
module that imports ``rerun`` (an optional extra), and only inside its functions."""

from __future__ import annotations

import hashlib
import uuid
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from cell.errors import UsageError
from cell.geometry import FloatArray
from cell.outputs import write_atomic
from cell.preview.page import draw_inputs
from cell.preview.timeline import quaternions_xyzw
from cell.preview.views import ARC_COLOUR, MM, PATH_COLOUR, STATUS_COLOURS, TRUTH_COLOUR, seam_lines, thin
from cell.types import CellView, ShapeKind
from cell.types.view import EYE, MOTION_HZ, TCP

if TYPE_CHECKING:
    from cell.pipeline.records import WeldRun

APPLICATION_ID = "weld-cell"
# no square brackets: the CLI prints error messages as rich markup, which would eat "[rerun]" of weld-cell's extra
INSTALL_HINT = "pip install 'weld-cell[rerun]' (in a checkout: uv sync --extra rerun)"
RATE_HZ = MOTION_HZ  # robot poses per second of motion on the timeline (the run's view holds them)
MAX_POINTS = 400_000  # cloud points kept (every k-th beyond this)


def require_rerun() -> None:
    """Before any work: UsageError (exit 2) naming how to install the extra when rerun-sdk is missing."""
    try:
        import rerun  # noqa: F401
    except ImportError:
        raise UsageError(f"--rerun needs the optional rerun-sdk package: {INSTALL_HINT}") from None


def recording_id(run: WeldRun) -> str:
    """A UUID derived from the run: its scenario (every resolved value), method and whether the arm moved."""
    det = run.detection
    key = f"{det.scenario.model_dump_json()}|{det.method}|{'weld' if run.execution is not None else 'preview'}"
    return str(uuid.UUID(bytes=hashlib.sha256(key.encode()).digest()[:16], version=5))


def _rgb(hex_colour: str) -> tuple[int, int, int]:
    h = hex_colour.lstrip("#")
    return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16)


def _height_colours(p: npt.ArrayLike) -> npt.NDArray[np.uint8]:
    z = np.asarray(p, dtype=float).reshape(-1, 3)[:, 2]
    u = (z - z.min()) / max(float(np.ptp(z)), 1e-9) if len(z) else z
    lo, hi = np.array([40, 70, 140]), np.array([250, 230, 90])
    return np.asarray(lo + u[:, None] * (hi - lo), dtype=np.uint8)


def _log_scene(rec: Any, rr: Any, run: WeldRun, max_points: int, moving: frozenset[str]) -> None:
    """The static cell: cloud, table, map parts, seams, cameras (those in ``moving`` ride on the arm: their pose is
    on the timeline)."""
    det = run.detection
    cloud, views, _, _ = draw_inputs(run)
    rec.log("cell", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    if len(cloud):
        p = thin(cloud, max_points).astype(np.float32)
        rec.log("cell/cloud", rr.Points3D(p, colors=_height_colours(p), radii=0.001), static=True)
    parts = tuple(pt for pt in det.weldmap_R.parts if pt.is_box)
    for pt in det.weldmap_R.parts:
        if not pt.is_box:  # any other body: its own triangulation
            vertices, triangles = pt.triangles()
            rec.log(
                f"cell/map/meshes/{pt.name}",
                rr.Mesh3D(vertex_positions=np.asarray(vertices, np.float32), triangle_indices=triangles),
                static=True,
            )
    if parts:
        X = np.array([pt.box.X_AB for pt in parts])
        rec.log(
            "cell/map/parts",
            rr.Boxes3D(
                centers=X[:, :3, 3], half_sizes=[pt.box.size / 2.0 for pt in parts],
                quaternions=quaternions_xyzw(X[:, :3, :3]), labels=[pt.name for pt in parts], colors=(90, 90, 90),
            ),
            static=True,
        )  # fmt: skip
    lines = seam_lines(views, det.weldmap_R)
    for status, colour in STATUS_COLOURS.items():
        mine = [ln for ln in lines if ln.status == status]
        if mine:
            rec.log(
                f"cell/seams/{status}",
                rr.LineStrips3D([ln.pts / MM for ln in mine], labels=[ln.id for ln in mine], colors=_rgb(colour),
                                radii=0.003),
                static=True,
            )  # fmt: skip
    truth = [ln for ln in lines if ln.truth is not None]
    if truth:
        strips = [np.asarray(ln.truth) / MM for ln in truth]
        rec.log(
            "cell/seams/truth",
            rr.LineStrips3D(strips, labels=[ln.id for ln in truth], colors=_rgb(TRUTH_COLOUR), radii=0.001),
            static=True,
        )
    view = run.view or CellView()
    if view.table is not None:
        t = view.table
        rec.log(
            "cell/table",
            rr.Boxes3D(centers=[t.X_AB[:3, 3]], half_sizes=[t.size / 2.0], quaternions=quaternions_xyzw(t.X_AB[:3, :3]),
                       colors=(200, 184, 154), fill_mode="solid"),
            static=True,
        )  # fmt: skip
    for cam in view.cameras:
        k = cam.intrinsics
        path = f"cell/cameras/{cam.name}"
        if cam.name not in moving:
            rec.log(path, rr.Transform3D(translation=cam.X_RC[:3, 3], mat3x3=cam.X_RC[:3, :3]), static=True)
        rec.log(
            path,
            rr.Pinhole(
                focal_length=[k.fx, k.fy], principal_point=[k.cx, k.cy], width=k.width, height=k.height,
                camera_xyz=rr.ViewCoordinates.RDF, image_plane_distance=cam.range_m,
            ),
            static=True,
        )  # fmt: skip


def _log_robot_shapes(rec: Any, rr: Any, view: CellView) -> None:
    """Each link's URDF solids, static, in the link's own frame (its pose is logged on the timeline)."""
    for link in view.links:
        mine = [s for s in view.shapes if s.link == link]
        for kind in ShapeKind:
            sol = [s for s in mine if s.kind is kind]
            if not sol:
                continue
            X = np.array([s.X_LS for s in sol])
            c, q = X[:, :3, 3], quaternions_xyzw(X[:, :3, :3])
            size = np.array([s.size for s in sol])
            rgb = [tuple(round(255 * v) for v in s.rgba[:3]) for s in sol]
            if kind is ShapeKind.BOX:
                arch = rr.Boxes3D(centers=c, half_sizes=size / 2.0, quaternions=q, colors=rgb, fill_mode="solid")
            elif kind is ShapeKind.CYLINDER:
                arch = rr.Cylinders3D(
                    centers=c, lengths=size[:, 2], radii=size[:, 0] / 2.0, quaternions=q, colors=rgb, fill_mode="solid"
                )
            else:
                arch = rr.Ellipsoids3D(centers=c, half_sizes=size / 2.0, quaternions=q, colors=rgb, fill_mode="solid")
            rec.log(f"cell/robot/{link}/{kind.value}", arch, static=True)


def _log_motion(rec: Any, rr: Any, run: WeldRun, moving: frozenset[str]) -> None:
    """The robot's links, the cameras riding on it, the TCP, the arc and the joints on the ``time`` timeline."""
    view = run.view or CellView()
    mo = view.motion
    if mo is None:
        if view.poses:  # no motion: the scan pose at time 0
            rec.set_time("time", duration=0.0)
            for link, X in view.poses[0].X_RL.items():
                rec.log(f"cell/robot/{link}", rr.Transform3D(translation=X[:3, 3], mat3x3=X[:3, :3]))
        return
    col = [rr.TimeColumn("time", duration=mo.times_s)]
    paths = [(link, f"cell/robot/{link}") for link in mo.X_RL if link not in (TCP, EYE)]
    paths += [(EYE, f"cell/cameras/{name}") for name in sorted(moving) if EYE in mo.X_RL]
    for link, path in paths:
        X = mo.X_RL[link]
        rec.send_columns(
            path, indexes=col, columns=rr.Transform3D.columns(translation=X[:, :3, 3], mat3x3=X[:, :3, :3])
        )
    if TCP in mo.X_RL:
        p_now = mo.X_RL[TCP][:, :3, 3]
        rec.send_columns("cell/tcp/now", indexes=col, columns=rr.Points3D.columns(positions=p_now))
    _log_tool_path(rec, rr, mo.tool_R, mo.tool_arc)
    rec.send_columns("plots/arc", indexes=col, columns=rr.Scalars.columns(scalars=mo.arc.astype(float)))
    q = mo.q
    names = run.plan.joint_names if run.plan is not None else tuple(f"q{j + 1}" for j in range(q.shape[1]))
    for j, name in enumerate(names):
        rec.send_columns(f"plots/joints/{name}", indexes=col, columns=rr.Scalars.columns(scalars=np.degrees(q[:, j])))
    for tm, text in mo.marks:
        rec.set_time("time", duration=tm)
        rec.log("log", rr.TextLog(text, level="INFO"))


def _log_tool_path(rec: Any, rr: Any, p: FloatArray, arc: npt.NDArray[np.bool_]) -> None:
    """The whole tool path (static): travel in one strip, every arc-on stretch a strip of its own."""
    if len(p) == 0:
        return
    rec.log("cell/tcp/path", rr.LineStrips3D([p], colors=_rgb(PATH_COLOUR), radii=0.0015), static=True)
    edges = np.flatnonzero(np.diff(np.r_[0, arc.astype(np.int8), 0]))
    welds = [p[a : b + 1] for a, b in zip(edges[::2], edges[1::2], strict=True) if b > a]
    if welds:
        rec.log("cell/tcp/arc_on", rr.LineStrips3D(welds, colors=_rgb(ARC_COLOUR), radii=0.003), static=True)


def _blueprint() -> Any:
    """The default layout: the cell in 3D beside the joints, the arc and the log, all on the ``time`` timeline."""
    import rerun.blueprint as rrb

    side = rrb.Vertical(
        rrb.TimeSeriesView(origin="plots/joints", name="joints [deg]"),
        rrb.TimeSeriesView(origin="plots/arc", name="arc on"),
        rrb.TextLogView(origin="log", name="motion"),
        row_shares=[3, 1, 2],
    )
    return rrb.Blueprint(
        rrb.Horizontal(rrb.Spatial3DView(origin="cell", name="cell (frame R)"), side, column_shares=[3, 2])
    )


def record_run(run: WeldRun, path: str | Path, *, max_points: int = MAX_POINTS) -> Path:
    """Write the run's Rerun recording (module docstring) to ``path`` in one piece; returns ``path``.

    UsageError when rerun-sdk is missing, OutputError when the file cannot be written.
    """
    require_rerun()
    import rerun as rr

    det = run.detection
    rec = rr.RecordingStream(application_id=APPLICATION_ID, recording_id=recording_id(run))
    rec.set_log_time_enabled(False)  # the wall clock would make the "time" timeline one of two
    stream = rr.binary_stream(recording=rec)
    rec.send_recording_name(f"{det.scenario.name} · {det.method} · {'weld' if run.execution else 'preview'}")
    cams = run.view.cameras if run.view is not None else ()
    mo = run.view.motion if run.view is not None else None
    on_arm = mo is not None and EYE in mo.X_RL
    moving = frozenset(c.name for c in cams if c.mount == "eye_in_hand" and on_arm)
    _log_scene(rec, rr, run, max_points, moving)
    if run.view is not None:
        _log_robot_shapes(rec, rr, run.view)
    _log_motion(rec, rr, run, moving)
    rec.send_blueprint(_blueprint(), make_active=True, make_default=True)
    data = stream.read(flush=True)
    rec.disconnect()
    return write_atomic(path, bytes(data or b""), what="Rerun recording")
