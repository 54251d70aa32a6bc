"""The cell around the part as values for pictures, computed once per run so that the preview reads values only: the
table, the robot's URDF shapes and link poses at the scan pose and along the plan, the cameras. Frame R, metres."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from cell.errors import ScenarioError
from cell.geometry import FloatArray, invert, make_pose, pose_from_xyz_rpy
from cell.scenario import Scenario
from cell.station.ports import Arm
from cell.types import Box, CameraIntrinsics, WeldPlan
from cell.types.view import CameraView, CellView, RobotPose, Shape, ShapeKind

PATH_POSES = 48  # robot poses drawn along the plan (evenly in time, plus every weld's start and end)
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


def cell_view(scenario: Scenario, arm: Arm | None, plan: WeldPlan | None) -> CellView:
    """The cell around the part in R (module docstring): the table, the robot's shapes and poses, the cameras."""
    X_RW = invert(scenario.X_WR)
    table = Box(X_RW @ make_pose(p=scenario.table.center_m), np.asarray(scenario.table.size_m, dtype=float))
    shapes: tuple[Shape, ...] = ()
    poses: tuple[RobotPose, ...] = ()
    if arm is not None:
        shapes = tuple(s for s in urdf_shapes(arm.model.source) if s.link in arm.model.frame_names)
        poses = robot_poses(arm, tuple(dict.fromkeys(s.link for s in shapes)), plan)
    return CellView(table, shapes, poses, cameras_R(scenario))
