"""The cell around the part as values for pictures, computed once per run so that the preview reads values only: the
table, the robot's URDF shapes and link poses at the scan pose, along the plan and along the motion, its joint
limits, the cameras. Frame R, metres."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from cell.errors import ScenarioError
from cell.geometry import FloatArray, invert, make_pose, pose_from_xyz_rpy, transform_points
from cell.scenario import Scenario
from cell.station.ports import Arm
from cell.types import Box, CameraIntrinsics, WeldPlan
from cell.types.view import EYE, MOTION_HZ, TCP, ArmMotion, CameraView, CellView, RobotPose, Shape, ShapeKind

if TYPE_CHECKING:
    from cell.types.execution import Execution
    from cell.types.trajectory import Trajectory

PATH_POSES = 48  # robot poses drawn along the plan (evenly in time, plus every weld's start and end)
TOOL_HZ = 50.0  # planned tool path samples per second (a preview's: nothing was executed)
_GREY = (0.6, 0.6, 0.6, 1.0)


def _floats(text: str | None, n: int, default: float = 0.0) -> list[float]:
    vals = [float(v) for v in text.split()] if text else [default] * n
    if len(vals) != n:
        raise ValueError(f"expected {n} numbers, got {text!r}")
    return vals


def _rgba(material: ET.Element, default: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """A URDF material's colour (its ``color rgba``), else ``default`` (a named material defined elsewhere)."""
    c = material.find("color")
    if c is None:
        return default
    r, g, b, a = _floats(c.get("rgba"), 4, 1.0)
    return (r, g, b, a)


def urdf_shapes(urdf: str | Path) -> tuple[Shape, ...]:
    """The visual solids of every link of a URDF, in its link frames (meshes skipped: nothing to draw offline).

    Raises ScenarioError when the file cannot be read as a URDF.
    """
    try:
        root = ET.parse(str(urdf)).getroot()
    except (OSError, ET.ParseError) as exc:
        raise ScenarioError(f"robot URDF {urdf} cannot be read: {exc}") from exc
    colours = {str(m.get("name")): _rgba(m, _GREY) for m in root.findall("material") if m.get("name")}
    out: list[Shape] = []
    for link in root.findall("link"):
        name = str(link.get("name"))
        for vis in link.findall("visual"):
            geom = vis.find("geometry")
            if geom is None or len(geom) == 0:
                continue
            el = geom[0]
            origin = vis.find("origin")
            xyz = _floats(origin.get("xyz") if origin is not None else None, 3)
            rpy = _floats(origin.get("rpy") if origin is not None else None, 3)
            material = vis.find("material")
            rgba = _GREY if material is None else _rgba(material, colours.get(str(material.get("name")), _GREY))
            if el.tag == "box":
                kind, size = ShapeKind.BOX, _floats(el.get("size"), 3)
            elif el.tag == "cylinder":
                d = 2.0 * float(el.get("radius", "0"))
                kind, size = ShapeKind.CYLINDER, [d, d, float(el.get("length", "0"))]
            elif el.tag == "sphere":
                kind, size = ShapeKind.SPHERE, [2.0 * float(el.get("radius", "0"))] * 3
            else:
                continue
            out.append(Shape(name, kind, pose_from_xyz_rpy(xyz, rpy), np.array(size), rgba))
    return tuple(out)


def robot_poses(arm: Arm, links: tuple[str, ...], plan: WeldPlan | None, n: int = PATH_POSES) -> tuple[RobotPose, ...]:
    """The links' poses X_RL at the scan pose, then at ``n`` instants along the plan (evenly in time, plus every
    weld's start and end), each labelled by what the arm does then."""
    links = tuple(f for f in links if f in arm.model.frame_names)
    poses = [RobotPose("scan pose", arm.model.fk_frames(arm.q_scan, links))]
    if plan is None or not plan.segments:
        return tuple(poses)
    times = np.linspace(0.0, plan.cycle_time, n)
    welds = [s for s in plan.segments if s.arc_on]
    times = np.unique(np.r_[times, [s.t0 for s in welds], [s.t1 for s in welds]].round(6))
    for t in times:
        seg = next((s for s in plan.segments if s.t0 - 1e-9 <= t <= s.t1 + 1e-9 and s.arc_on), None)
        if seg is None:
            seg = next((s for s in plan.segments if s.t0 - 1e-9 <= t <= s.t1 + 1e-9), plan.segments[-1])
        what = f"weld {seg.seam_id}" if seg.arc_on else f"{seg.kind} {seg.seam_id}".strip()
        q, _, _ = plan.sample(float(t))
        frames = arm.model.fk_frames(q, links)
        if plan.track is not None:  # the base where the carriage has it (docs/track.md): every link moves with it
            d_R = plan.track.offset_R(float(seg.trajectory.e1_at(float(t) - seg.t0)))
            frames = {k: _shifted(X, d_R) for k, X in frames.items()}
        poses.append(RobotPose(f"{t:.1f} s · {what}", frames, float(t)))
    return tuple(poses)


def _shifted(X_RL: FloatArray, d_R: FloatArray) -> FloatArray:
    """X_RL (4, 4) moved by d_R (3,) [m] in R."""
    X = np.array(X_RL, dtype=float)
    X[:3, 3] += d_R
    return X


def cameras_R(scenario: Scenario) -> tuple[CameraView, ...]:
    """The scenario's cameras in R: optical frames (the eye-in-hand camera at its scan viewpoint), pinhole
    intrinsics from resolution and field of view, frusta drawn to the camera's target."""
    X_RW = invert(scenario.X_WR)
    out = []
    for name, cam in scenario.cameras.items():
        w, h = cam.resolution
        f = cam.fx_px
        k = CameraIntrinsics(w, h, f, f, (w - 1) / 2.0, (h - 1) / 2.0)
        rng = math.dist(cam.eye_m, cam.target_m)
        out.append(CameraView(name, X_RW @ cam.X_WC, k, cam.mount, rng))
    return tuple(out)


def subsample(times: FloatArray, arc: npt.NDArray[np.bool_], rate_hz: float) -> npt.NDArray[np.intp]:
    """Indices of the samples kept: the first at or after every 1/rate_hz, every arc switch (both sides), the last."""
    grid = np.arange(times[0], times[-1], 1.0 / rate_hz)
    idx = np.searchsorted(times, grid - 1e-9)
    switch = np.flatnonzero(np.diff(arc.astype(np.int8)) != 0)
    return np.unique(np.clip(np.r_[idx, switch, switch + 1, len(times) - 1], 0, len(times) - 1))


def _event_text(plan: WeldPlan, pre: Trajectory | None, t: float, kind: str, detail: str) -> str:
    """An execution event as a line of the log: a move mark as it is, an arc switch with its seam's id."""
    if kind == "move":
        return detail
    off = pre.duration if pre is not None else 0.0
    welds = [s for s in plan.segments if s.arc_on]
    seam = next((s.seam_id for s in welds if min(abs(off + s.t0 - t), abs(off + s.t1 - t)) < 0.02), "")
    return f"{kind} {seam} ({detail})" if seam else f"{kind} ({detail})"


def _timeline(
    plan: WeldPlan, pre: Trajectory | None, ex: Execution | None
) -> tuple[FloatArray, FloatArray, npt.NDArray[np.bool_], tuple[tuple[float, str], ...]]:
    """The motion's times (n,) [s], q (n, dof) [rad], arc (n,) and marks: what the arm did when it moved, else the
    plan's (the move from the scan pose home, then the program)."""
    if ex is not None:
        done = tuple((float(e.t), _event_text(plan, pre, e.t, e.kind, e.detail)) for e in ex.events)
        return np.asarray(ex.times, dtype=float), np.asarray(ex.q, dtype=float), np.asarray(ex.arc_on), done
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


def arm_motion(
    arm: Arm,
    links: tuple[str, ...],
    plan: WeldPlan | None,
    pre: Trajectory | None = None,
    ex: Execution | None = None,
    X_RW: FloatArray | None = None,
) -> ArmMotion | None:
    """The arm's motion for pictures (:class:`~cell.types.view.ArmMotion`): ``links`` (with the TCP and the
    eye-in-hand camera's frame, those the arm has) posed by its forward kinematics every 1/MOTION_HZ and at every
    arc switch; the tool path executed (``ex``'s TCP, carried into R by ``X_RW``), else planned (every 1/TOOL_HZ).
    None without a plan."""
    if plan is None or not plan.segments:
        return None
    times, q, arc, marks = _timeline(plan, pre, ex)
    idx = subsample(times, arc, MOTION_HZ)
    frames = tuple(f for f in dict.fromkeys((*links, TCP, EYE)) if f in arm.model.frame_names)
    poses = [arm.model.fk_frames(q[i], frames) for i in idx]
    X_RL = {f: np.array([p[f] for p in poses]) for f in frames}
    if ex is not None:
        tool_R, tool_arc = transform_points(X_RW if X_RW is not None else np.eye(4), ex.tcp_W), arc
    elif TCP in frames:
        keep = subsample(times, arc, TOOL_HZ)
        tool_R, tool_arc = np.array([arm.model.fk_frames(q[i], (TCP,))[TCP][:3, 3] for i in keep]), arc[keep]
    else:
        tool_R, tool_arc = np.zeros((0, 3)), np.zeros(0, bool)
    return ArmMotion(times[idx], q[idx], arc[idx], X_RL, tool_R, tool_arc, marks, MOTION_HZ)


def cell_view(
    scenario: Scenario,
    arm: Arm | None,
    plan: WeldPlan | None,
    pre: Trajectory | None = None,
    execution: Execution | None = None,
) -> CellView:
    """The cell around the part in R (module docstring): the table, the robot's shapes and poses, the cameras; the
    arm's motion (the move home ``pre`` and the plan, or what the arm did: ``execution``) and its joint limits."""
    X_RW = invert(scenario.X_WR)
    table = Box(X_RW @ make_pose(p=scenario.table.center_m), np.asarray(scenario.table.size_m, dtype=float))
    if arm is None:
        return CellView(table, (), (), cameras_R(scenario))
    shapes = tuple(s for s in urdf_shapes(arm.model.source) if s.link in arm.model.frame_names)
    links = tuple(dict.fromkeys(s.link for s in shapes))
    poses = robot_poses(arm, links, plan)
    motion = arm_motion(arm, links, plan, pre, execution, X_RW)
    return CellView(table, shapes, poses, cameras_R(scenario), motion, arm.model.limits)
