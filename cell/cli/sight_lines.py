"""``cell scenario check``'s seams as the cameras will see them: one line per seam (which cameras of the first scan see
its two faces, at what incidence and range) and one warning per seam the first scan will not see, with what would
help (a fixed camera's place that sees it, the close-up re-scan's planned view). Predicted from the map at its
nominal place by the pipeline's own view test (:mod:`cell.rescan.sight`, :mod:`cell.pipeline.closeup_plan`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cell.errors import CellError
from cell.geometry import FloatArray
from cell.rescan.sight import (
    NO_TORCH,
    CameraSight,
    SeamSight,
    camera_lens,
    camera_sight,
    first_scan_sight,
    occluders,
    seam_target,
)
from cell.rescan.view_grid import ViewOptions, torch_axis_in_camera
from cell.scenario import CameraSpec, Scenario
from cell.types import WeldMap
from cell.types.rescan import PlannedCloseup


@dataclass(frozen=True)
class SightReport:
    """The lines to print (one per seam) and the warnings (one per seam the first scan will not see)."""

    lines: tuple[str, ...]
    warnings: tuple[str, ...]


def _who(c: CameraSight, scn: Scenario, faces: Sequence[int] = (0, 1)) -> str:
    mount = " at its scan pose" if scn.cameras[c.camera].mount == "eye_in_hand" else ""
    inc = "/".join(f"{c.incidence_deg[k]:.0f}" for k in faces)
    return f"{c.camera}{mount} ({inc} deg{', grazing' if c.grazing else ''}, {c.range_m:.2f} m)"


def _why_not(s: SeamSight, face: int) -> str:
    """Why each camera misses one face, grouped: ``edge-on to cam_left, cam_right; out of eye_in_hand's image``."""
    by: dict[str, list[str]] = {}
    for c in s.cameras:
        b = c.blind[face]
        if b is not None:
            by.setdefault(b.value, []).append(c.camera)
    return "; ".join(
        f"{why} of {', '.join(names)}" if why.startswith("out of") else f"{why} to {', '.join(names)}"
        for why, names in by.items()
    )


def seam_line(s: SeamSight, scn: Scenario) -> str:
    """One seam as the first scan's cameras will see it."""
    if s.underside:
        return f"{s.seam_id}: against the table: seen after the part is turned over (flip.allowed, --sides all)"
    whole = s.seen_by
    if whole:
        return f"{s.seam_id}: both faces seen by " + ", ".join(_who(c, scn) for c in whole)
    parts = []
    for k in (0, 1):
        by = s.face_seen_by(k)
        seen = ", ".join(_who(c, scn, (k,)) for c in by) if by else f"no camera ({_why_not(s, k)})"
        parts.append(f"face {s.faces[k]} by {seen}")
    return f"{s.seam_id}: " + "; ".join(parts)


def _suggest(scn: Scenario, weldmap_W: WeldMap, seam_id: str) -> str:
    """A fixed camera's place (about the seam, as ``cell init`` places them) that sees both faces of the seam."""
    from cell.scenario.camera_layout import CAMERA_UP, camera_candidates
    from cell.seams.joint import find_joints

    joint = find_joints(weldmap_W)[seam_id]
    target, parts = seam_target(weldmap_W, joint), occluders(weldmap_W, joint)
    top = max(float(p.vertices()[:, 2].max()) for p in weldmap_W.parts)
    view = scn.rescan.closeup.view
    best: tuple[float, str] | None = None
    for _, eye, look_at in camera_candidates(target.mid, top):
        spec = CameraSpec(eye_m=_v(eye), target_m=_v(look_at), up=CAMERA_UP)
        c = camera_sight(camera_lens("new", spec, view), target, parts, scn.table.top_z, view)
        if c.seen and (best is None or max(c.incidence_deg) < best[0] - 10.0):
            where = f"a fixed camera at {_m(eye)} looking at {_m(look_at)} would see both faces"
            best = (max(c.incidence_deg), f"{where} ({c.incidence_deg[0]:.0f}/{c.incidence_deg[1]:.0f} deg)")
    return best[1] if best is not None else "no fixed camera about the seam sees both faces (another part hides one)"


def _closeup_words(p: PlannedCloseup | None, why: str) -> str:
    if p is None:
        return f"no close-up: {why}"
    if p.served_by:
        return f"the close-up of {p.served_by} will see it"
    if p.viewpoint is None:
        return f"no close-up view either ({p.reason})"
    vp = p.viewpoint
    return (
        f"the close-up will: a view from {vp.distance_m:.2f} m at {vp.incidence_deg[0]:.0f}/{vp.incidence_deg[1]:.0f}"
        " deg is reachable (rescan.mode low re-scans a seam not found)"
    )


def arm_torch(urdf: str, view: ViewOptions) -> FloatArray:
    """(n, 3) the torch's axis in the arm camera's image, for the robot ``urdf`` (in the repository's robots/)."""
    from cell.motion.robot import RobotModel
    from cell.station.arm import ROBOT_DIR

    return torch_axis_in_camera(RobotModel.from_urdf(ROBOT_DIR / urdf), view)


def sight_report(scn: Scenario, weldmap_M: WeldMap) -> SightReport:
    """Every seam's line and the warnings, for ``scn`` with its map (frame M) at its nominal place."""
    from cell.pipeline.closeup_plan import nominal_closeups

    arm = scn.robot.urdf is not None and any(c.mount == "eye_in_hand" for c in scn.cameras.values())
    torch_C = arm_torch(str(scn.robot.urdf), scn.rescan.closeup.view) if arm else NO_TORCH
    sights = first_scan_sight(scn, weldmap_M, torch_C)
    lines = tuple(seam_line(s, scn) for s in sights)
    blind = [s for s in sights if not s.underside and not s.seen]
    if not blind:
        return SightReport(lines, ())
    why = ""
    planned: dict[str, PlannedCloseup] = {}
    try:
        planned = {p.seam_id: p for p in nominal_closeups(scn, weldmap_M, [s.seam_id for s in blind])}
    except CellError as exc:
        why = exc.message
    weldmap_W = weldmap_M.transformed(scn.X_WM, "W")
    warnings = []
    for s in blind:
        faces = [s.faces[k] for k in (0, 1) if not s.face_seen_by(k)]
        warnings.append(
            f"seam {s.seam_id}: no camera of the first scan sees face {' nor '.join(faces)}; "
            f"{_suggest(scn, weldmap_W, s.seam_id)}; {_closeup_words(planned.get(s.seam_id), why)}"
        )
    return SightReport(lines, tuple(warnings))


def _v(p: FloatArray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))


def _m(p: FloatArray) -> str:
    """A world point in metres, as the scenario writes it: ``[0.15, 0.85, 2.06] m``."""
    return "[" + ", ".join(f"{float(x):.2f}" for x in np.asarray(p)) + "] m"


__all__ = ["SightReport", "arm_torch", "seam_line", "sight_report"]
