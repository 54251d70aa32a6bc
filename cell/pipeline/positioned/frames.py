"""What the positioner's planning reads from a detection at home: each located seam in the faceplate frame (its
direction, its faces' normals from the aligned map, its points), the positioner's move time, and the true seams
where the part lies now (a simulator's, for measuring only)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cell.geometry import FloatArray, transform_points
from cell.pipeline.records import Detection
from cell.positioner.poses import SeamFrame
from cell.station import Station
from cell.types import JointLimits, WeldMap
from cell.types.positioner import TiltRotatePositioner

WAYPOINTS = 5  # points along a seam at which its position is checked


def seam_frames(det: Detection, pos: TiltRotatePositioner, ids: Sequence[str], target: str = "PB") -> list[SeamFrame]:
    """The seams ``ids`` (found) in F at home: direction and the weld faces' outward normals (the aligned map's)
    at ``WAYPOINTS`` points from start to end, each asking ``target``."""
    from cell.planning.tasks import seam_tasks

    assert det.scene is not None
    ss = det.scene.seam_scene
    keep = set(ids)
    tasks = seam_tasks([e for e in det.estimates if e.id in keep], ss.weldmap, ss.joints, None)
    X_FR = np.linalg.inv(pos.X_R_F(*pos.home))
    R = X_FR[:3, :3]
    out = []
    for t in tasks:
        s = np.linspace(0.0, 1.0, WAYPOINTS)[:, None]
        p_R = t.p_start + s * (t.p_end - t.p_start)
        d = np.broadcast_to(R @ (t.p_end - t.p_start), (WAYPOINTS, 3))
        n_a = np.broadcast_to(R @ t.n_a, (WAYPOINTS, 3))
        n_b = np.broadcast_to(R @ t.n_b, (WAYPOINTS, 3))
        out.append(SeamFrame(t.id, d, n_a, n_b, transform_points(np.asarray(X_FR, dtype=float), p_R), target))
    return out


def axes_move_s(pos: TiltRotatePositioner, a: tuple[float, float], b: tuple[float, float]) -> float:
    """[s]: both axes from ``a`` to ``b`` (tilt, rotate) [rad], jerk-limited, synchronised (Ruckig)."""
    from cell.motion.timing import ptp_duration

    if np.allclose(a, b):
        return 0.0
    t, r = pos.tilt, pos.rotate
    lim = JointLimits(
        ("tilt", "rotate"),
        np.array([t.q_min, r.q_min]),
        np.array([t.q_max, r.q_max]),
        np.array([t.v_max, r.v_max]),
        np.array([t.a_max, r.a_max]),
        np.array([t.j_max, r.j_max]),
    )
    return ptp_duration(np.array(a), np.array(b), lim)


def truths_at(
    station: Station, det: Detection, weldmap_M: WeldMap, X_WM: FloatArray
) -> dict[str, tuple[FloatArray, FloatArray]]:
    """The true seams (R) of the part as the station holds it now, the map's nominal placement ``X_WM`` ordering
    their ends (empty when the station knows no truth)."""
    from cell.seams.truth import true_seams

    parts_W = station.truth()
    if parts_W is None or det.scene is None:
        return {}
    sc = det.scenario
    return true_seams(weldmap_M.transformed(X_WM, "W"), det.scene.seam_scene.joints, parts_W, sc.X_WR)


def drawn_frames(det: Detection, pos: TiltRotatePositioner, ids: Sequence[str], target: str = "PB") -> list[SeamFrame]:
    """:func:`seam_frames` of seams not located (the underside's), from the aligned map's drawn seams: where a pose
    could hold them (asking ``target``) and the close-up could find them."""
    from dataclasses import replace

    from cell.types import SeamEstimate, SeamStatus

    keep = set(ids)
    drawn = [
        SeamEstimate(s.id, SeamStatus.FOUND, p_start=s.p_start, p_end=s.p_end)
        for s in det.weldmap_R.seams
        if s.id in keep
    ]
    return seam_frames(replace(det, estimates=tuple(drawn)), pos, [e.id for e in drawn], target)
