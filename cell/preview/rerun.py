"""A Rerun recording of a run (``cell weld --rerun FILE.rrd``, ``cell preview --rerun FILE.rrd``).

The only module that imports ``rerun`` (an optional extra: ``pip install 'weld-cell[rerun]'``), and only inside
its functions. It writes, from the values the HTML page draws (the run's records and its
:class:`~cell.types.CellView`), everything in the robot frame R [m] under ``cell/``:

- ``cell/cloud``: the dense cloud (coloured by height); ``cell/table``; ``cell/map/parts``: the aligned map's
  parts as boxes; ``cell/seams/<status>``: the estimated seams (where nothing was found: the map's) as lines
  coloured like the page (:data:`~cell.preview.views.STATUS_COLOURS`), ``cell/seams/truth`` the true seams;
- ``cell/cameras/<name>``: each camera's pose X_RC and pinhole (the eye-in-hand camera at its scan viewpoint);
- ``cell/robot/<link>``: the link's URDF shapes, posed along the motion on the ``time`` timeline; ``cell/tcp``:
  the tool path (arc-on stretches one strip per weld) and the TCP now; ``plots/arc`` (0/1) and
  ``plots/joints/<joint>`` [deg]; ``log``: the motion's marks (move, arc on, arc off).

Time ``time`` [s] is the execution's: 0 is the arm at its scan pose (where the cloud was taken), then the move
home and the welding program. A weld run uses what the arm did (the execution's record); a preview the plan.
The 1 kHz motion is subsampled to ``rate_hz`` (plus every arc switch); the link poses at those instants come from
the arm the run carries (its forward kinematics: a method of a value of the run, no stage imported).

The file is written in one piece (:func:`cell.export.atomic.write_atomic`); the recording id is derived from the
run (scenario, method, whether it moved), so two recordings of the same run open as the same recording.
"""

from __future__ import annotations

import hashlib
import uuid
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from cell.errors import UsageError
from cell.export.atomic import write_atomic
from cell.geometry import FloatArray, invert, transform_points
from cell.preview.page import draw_inputs
from cell.preview.views import ARC_COLOUR, MM, PATH_COLOUR, STATUS_COLOURS, TRUTH_COLOUR, seam_lines, thin
from cell.types import CellView, ShapeKind

if TYPE_CHECKING:
    from cell.pipeline.records import WeldRun

APPLICATION_ID = "weld-cell"
INSTALL_HINT = "uv sync --extra rerun, or pip install 'weld-cell[rerun]'"
RATE_HZ = 20.0  # robot poses per second of motion on the timeline
MAX_POINTS = 400_000  # cloud points kept (every k-th beyond this)
TCP = "torch_tcp"
Motion = tuple[FloatArray, FloatArray, npt.NDArray[np.bool_], tuple[tuple[float, str], ...]]
LinkPoses = Callable[[FloatArray, tuple[str, ...]], Mapping[str, FloatArray]]


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


def quaternions_xyzw(R: npt.ArrayLike) -> FloatArray:
    """(n, 4) unit quaternions (x, y, z, w) of rotation matrices (n, 3, 3) (Shepperd's method)."""
    m = np.asarray(R, dtype=float).reshape(-1, 3, 3)
    tr = np.trace(m, axis1=1, axis2=2)
    d = np.stack([m[:, 0, 0], m[:, 1, 1], m[:, 2, 2], tr], axis=1)
    k = np.argmax(d, axis=1)
    q = np.empty((len(m), 4))
    for i in range(len(m)):
        a = m[i]
        if k[i] == 3:
            s = 2.0 * np.sqrt(1.0 + tr[i])
            q[i] = [(a[2, 1] - a[1, 2]) / s, (a[0, 2] - a[2, 0]) / s, (a[1, 0] - a[0, 1]) / s, 0.25 * s]
        else:
            j, n = (k[i] + 1) % 3, (k[i] + 2) % 3
            s = 2.0 * np.sqrt(max(1.0 + a[k[i], k[i]] - a[j, j] - a[n, n], 1e-12))
            v = np.empty(4)
            v[k[i]] = 0.25 * s
            v[j] = (a[j, k[i]] + a[k[i], j]) / s
            v[n] = (a[n, k[i]] + a[k[i], n]) / s
            v[3] = (a[n, j] - a[j, n]) / s
            q[i] = v
    q *= np.where(q[:, 3:4] < 0.0, -1.0, 1.0)
    return np.asarray(q / np.linalg.norm(q, axis=1, keepdims=True))


def motion(run: WeldRun) -> Motion | None:
    """The arm's motion on the recording's time axis: times (n,) [s], q (n, dof) [rad], arc (n,) and the marks
    (time, text); what the arm did when it moved, else the plan's (move from the scan pose home, then the
    program); None without a plan."""
    ex, plan, pre = run.execution, run.plan, run.pre_move
    if ex is not None:
        done = tuple((float(e.t), _event_text(run, e.t, e.kind, e.detail)) for e in ex.events)
        return np.asarray(ex.times, dtype=float), np.asarray(ex.q, dtype=float), np.asarray(ex.arc_on), done
    if plan is None or not plan.segments:
        return None
    traj, arc = plan.joint_trajectory()
    t0 = pre.duration if pre is not None else 0.0
    times, q = traj.times + t0, np.asarray(traj.q)
    on = np.asarray(arc)
    if pre is not None:
        times = np.concatenate([pre.times, times[1:]])
        q = np.concatenate([pre.q, q[1:]])
        on = np.concatenate([np.zeros(len(pre.times), bool), on[1:]])
    marks: list[tuple[float, str]] = [(0.0, "move scan -> home")] if pre is not None else []
    for s in plan.segments:
        marks.append((t0 + s.t0, f"{s.kind} {s.seam_id}".strip()))
        if s.arc_on:
            marks += [(t0 + s.t0, f"arc_on {s.seam_id}"), (t0 + s.t1, f"arc_off {s.seam_id}")]
    return times, q, on, tuple(sorted(marks))


def _event_text(run: WeldRun, t: float, kind: str, detail: str) -> str:
    """An execution event as a line of the log: a move mark as it is, an arc switch with its seam's id."""
    if kind == "move":
        return detail
    off = run.pre_move.duration if run.pre_move is not None else 0.0
    welds = [s for s in run.plan.segments if s.arc_on] if run.plan is not None else []
    seam = next((s.seam_id for s in welds if min(abs(off + s.t0 - t), abs(off + s.t1 - t)) < 0.02), "")
    return f"{kind} {seam} ({detail})" if seam else f"{kind} ({detail})"


def subsample(times: FloatArray, arc: npt.NDArray[np.bool_], rate_hz: float) -> npt.NDArray[np.intp]:
    """Indices of the samples kept: the first at or after every 1/rate_hz, every arc switch (both sides), the last."""
    grid = np.arange(times[0], times[-1], 1.0 / rate_hz)
    idx = np.searchsorted(times, grid - 1e-9)
    switch = np.flatnonzero(np.diff(arc.astype(np.int8)) != 0)
    return np.unique(np.clip(np.r_[idx, switch, switch + 1, len(times) - 1], 0, len(times) - 1))


def _height_colours(p: npt.ArrayLike) -> npt.NDArray[np.uint8]:
    z = np.asarray(p, dtype=float).reshape(-1, 3)[:, 2]
    u = (z - z.min()) / max(float(np.ptp(z)), 1e-9) if len(z) else z
    lo, hi = np.array([40, 70, 140]), np.array([250, 230, 90])
    return np.asarray(lo + u[:, None] * (hi - lo), dtype=np.uint8)


def _log_scene(rec: Any, rr: Any, run: WeldRun, max_points: int) -> None:
    """The static cell: cloud, table, map parts, seams, cameras."""
    det = run.detection
    cloud, views, _, _ = draw_inputs(run)
    rec.log("cell", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    if len(cloud):
        p = thin(cloud, max_points).astype(np.float32)
        rec.log("cell/cloud", rr.Points3D(p, colors=_height_colours(p), radii=0.001), static=True)
    parts = det.weldmap_R.parts
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


def _log_motion(rec: Any, rr: Any, run: WeldRun, rate_hz: float, fk: LinkPoses | None) -> float:
    """The robot's links, the TCP, the arc and the joints on the ``time`` timeline; the seconds it spans."""
    view = run.view or CellView()
    mo = motion(run)
    if mo is None:
        if view.poses:  # no motion: the scan pose at time 0
            rec.set_time("time", duration=0.0)
            for link, X in view.poses[0].X_RL.items():
                rec.log(f"cell/robot/{link}", rr.Transform3D(translation=X[:3, 3], mat3x3=X[:3, :3]))
        return 0.0
    times, q, arc, marks = mo
    idx = subsample(times, arc, rate_hz)
    t = times[idx]
    col = [rr.TimeColumn("time", duration=t)]
    if fk is not None:
        links = tuple(dict.fromkeys((*view.links, TCP)))
        poses = [fk(q[i], links) for i in idx]
        for link in links:
            if link == TCP or link not in poses[0]:
                continue
            X = np.array([p[link] for p in poses])
            cols = rr.Transform3D.columns(translation=X[:, :3, 3], mat3x3=X[:, :3, :3])
            rec.send_columns(f"cell/robot/{link}", indexes=col, columns=cols)
        if TCP in poses[0]:
            p_now = np.array([p[TCP][:3, 3] for p in poses])
            rec.send_columns("cell/tcp/now", indexes=col, columns=rr.Points3D.columns(positions=p_now))
    _log_tool_path(rec, rr, run, times, q, arc, fk)
    rec.send_columns("plots/arc", indexes=col, columns=rr.Scalars.columns(scalars=arc[idx].astype(float)))
    names = run.plan.joint_names if run.plan is not None else tuple(f"q{j + 1}" for j in range(q.shape[1]))
    for j, name in enumerate(names):
        rec.send_columns(f"plots/joints/{name}", indexes=col, columns=rr.Scalars.columns(scalars=np.degrees(q[idx, j])))
    for tm, text in marks:
        rec.set_time("time", duration=tm)
        rec.log("log", rr.TextLog(text, level="INFO"))
    return float(times[-1] - times[0])


def _log_tool_path(
    rec: Any, rr: Any, run: WeldRun, times: FloatArray, q: FloatArray, arc: npt.NDArray[np.bool_], fk: LinkPoses | None
) -> None:
    """The whole tool path (static): travel in one strip, every arc-on stretch a strip of its own."""
    ex = run.execution
    if ex is not None:
        p = transform_points(invert(run.detection.scenario.X_WR), ex.tcp_W)
    elif fk is not None:
        keep = subsample(times, arc, 100.0)
        p, arc = np.array([fk(q[i], (TCP,))[TCP][:3, 3] for i in keep]), arc[keep]
    else:
        return
    rec.log("cell/tcp/path", rr.LineStrips3D([p], colors=_rgb(PATH_COLOUR), radii=0.0015), static=True)
    edges = np.flatnonzero(np.diff(np.r_[0, arc.astype(np.int8), 0]))
    welds = [p[a : b + 1] for a, b in zip(edges[::2], edges[1::2], strict=True) if b > a]
    if welds:
        rec.log("cell/tcp/arc_on", rr.LineStrips3D(welds, colors=_rgb(ARC_COLOUR), radii=0.003), static=True)


def record_run(
    run: WeldRun, path: str | Path, *, rate_hz: float = RATE_HZ, max_points: int = MAX_POINTS,
    link_poses: LinkPoses | None = None,
) -> Path:  # fmt: skip
    """Write the run's Rerun recording (module docstring) to ``path`` in one piece; returns ``path``.

    link_poses : (q (dof,), links) -> {link: X_RL (4, 4)}; default the run's arm's forward kinematics (without an
        arm the robot stays out). UsageError when rerun-sdk is missing, OutputError when the file cannot be written.
    """
    require_rerun()
    import rerun as rr

    det = run.detection
    fk = link_poses if link_poses is not None else (run.arm.model.fk_frames if run.arm is not None else None)
    rec = rr.RecordingStream(application_id=APPLICATION_ID, recording_id=recording_id(run))
    rec.set_log_time_enabled(False)  # the wall clock would make the "time" timeline one of two
    stream = rr.binary_stream(recording=rec)
    rec.send_recording_name(f"{det.scenario.name} · {det.method} · {'weld' if run.execution else 'preview'}")
    _log_scene(rec, rr, run, max_points)
    if run.view is not None:
        _log_robot_shapes(rec, rr, run.view)
    _log_motion(rec, rr, run, rate_hz, fk)
    data = stream.read(flush=True)
    rec.disconnect()
    return write_atomic(path, bytes(data or b""), what="Rerun recording")
