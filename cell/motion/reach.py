"""The reach pre-check: IK-free necessary conditions for a torch pose, to refuse an unreachable seam (or a candidate)
in microseconds with its reason before any IK is tried: the wrist centre against the shoulder's reach
(docs/planning.md section 1). Frames: R the robot base; T the TCP frame. Units: metres."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.motion.failures import SeamFailure
from cell.motion.process.torch import WeldProcess, fillet_axes
from cell.motion.robot import RobotModel
from cell.types.plan import PlanReason, SeamTask

_PAD_M = 1e-3  # [m] added to d_max: rounding of the fitted elbow law and of the FK, never a real reach


@dataclass(frozen=True)
class ReachModel:
    """The shoulder circle and the shoulder-wrist distance range of one arm (see the module docstring).

    centre_R (3,) a point of A1's axis; axis_R (3,) its unit direction; height [m] of the shoulder circle along
    it from centre_R, radius [m]; d_min, d_max [m] |S W| over A3's limits; p_TW (3,) the wrist centre in T.
    """

    centre_R: FloatArray
    axis_R: FloatArray
    height: float
    radius: float
    d_min: float
    d_max: float
    p_TW: FloatArray

    @classmethod
    def from_robot(
        cls,
        robot: RobotModel,
        shoulder: str = "link_2",
        wrist: str = "link_5",
        tool: str = "torch_tcp",
        elbow_joint: int = 2,
    ) -> ReachModel:
        """Measured on the arm's own kinematics by FK. ValueError when the arm is not of this kind (the wrist
        centre not rigid with the tool, or the distance not a function of the elbow joint)."""
        dof = robot.dof
        frames = (shoulder, wrist, tool)

        def at(q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
            f = robot.fk_frames(q, frames)
            return f[shoulder][:3, 3], f[wrist][:3, 3], f[tool]

        rng = np.random.default_rng(0)  # a fixed set of test configurations (no global RNG)
        lim = robot.limits
        qs = [lim.q_min + (lim.q_max - lim.q_min) * rng.random(dof) for _ in range(4)]
        p_TW = []
        for q in qs:
            _, w, X = at(q)
            p_TW.append(X[:3, :3].T @ (w - X[:3, 3]))
        if np.ptp(np.array(p_TW), axis=0).max() > 1e-6:
            raise ValueError(f"reach: {wrist} is not rigid with {tool} (no spherical wrist)")
        # the shoulder circle: S at three turns of A1 (the others at zero)
        s_pts = []
        for a in (0.0, 2.0, 4.0):
            q = np.zeros(dof)
            q[0] = a
            s_pts.append(at(q)[0])
        s0, s1, s2 = s_pts
        axis = np.cross(s1 - s0, s2 - s0)
        if np.linalg.norm(axis) < 1e-9:  # the shoulder on A1's axis: a circle of radius 0
            axis = np.array([0.0, 0.0, 1.0])
        axis = axis / np.linalg.norm(axis)
        centre = robot.reach_bound(tool)[0]
        v = s0 - centre
        height = float(v @ axis)
        radius = float(np.linalg.norm(v - height * axis))
        # |S W| against the elbow joint: d^2 = A + B cos q + C sin q (two links turning about parallel axes)
        q3 = np.linspace(lim.q_min[elbow_joint], lim.q_max[elbow_joint], 9)
        d2 = []
        for x in q3:
            q = np.zeros(dof)
            q[elbow_joint] = x
            s, w, _ = at(q)
            d2.append(float(np.sum((w - s) ** 2)))
        M = np.column_stack([np.ones_like(q3), np.cos(q3), np.sin(q3)])
        coef, *_ = np.linalg.lstsq(M, np.array(d2), rcond=None)
        if np.max(np.abs(M @ coef - d2)) > 1e-9:
            raise ValueError("reach: the shoulder-wrist distance is not a function of the elbow joint alone")
        A, B, C = coef
        amp, phase = float(np.hypot(B, C)), float(np.arctan2(C, B))
        lo, hi = float(lim.q_min[elbow_joint]), float(lim.q_max[elbow_joint])
        cands = [lo, hi] + [phase + k * np.pi for k in range(-4, 5) if lo < phase + k * np.pi < hi]
        vals = [A + amp * np.cos(x - phase) for x in cands]
        d_min = float(np.sqrt(max(min(vals), 0.0)))
        d_max = float(np.sqrt(max(vals))) + _PAD_M
        return cls(centre, axis, height, radius, max(d_min - _PAD_M, 0.0), d_max, np.mean(p_TW, axis=0))

    def circle_distance(self, p_R: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(nearest, farthest) distance [m] of points p_R (n, 3) from the shoulder circle, each (n,)."""
        v = np.atleast_2d(np.asarray(p_R, dtype=float)) - self.centre_R
        h = v @ self.axis_R - self.height
        rho = np.linalg.norm(v - np.outer(v @ self.axis_R, self.axis_R), axis=1)
        return np.hypot(h, rho - self.radius), np.hypot(h, rho + self.radius)

    def pose_excess(self, X_RT: npt.ArrayLike) -> FloatArray:
        """(n,) [m]: how far each TCP pose's wrist centre lies beyond the shoulder's reach (<= 0: may be
        reachable). X_RT (n, 4, 4) or (4, 4). A wrist centre nearer the shoulder than d_min counts too (as the
        distance short of d_min)."""
        X = np.asarray(X_RT, dtype=float).reshape(-1, 4, 4)
        p_RW = X[:, :3, 3] + X[:, :3, :3] @ self.p_TW
        near, far = self.circle_distance(p_RW)
        return np.maximum(near - self.d_max, self.d_min - far)

    def point_excess(self, p_R: npt.ArrayLike) -> FloatArray:
        """(n,) [m]: how far each TCP position p_R (n, 3) lies beyond reach for every torch orientation (<= 0:
        some orientation may reach it)."""
        near, _ = self.circle_distance(p_R)
        return near - (self.d_max + float(np.linalg.norm(self.p_TW)))


def cone_excess(
    reach: ReachModel,
    p_R: npt.ArrayLike,
    z_R: npt.ArrayLike,
    half_angle: float,
    standoff: float = 0.0,
) -> FloatArray:
    """(n,) [m]: how far the wrist centre lies beyond the shoulder's reach, at least, for every torch held at the
    seam points p_R (n, 3) with its axis z (into the joint) within ``half_angle`` [rad] of z_R (3,) (unit), any
    spin, the wire tip ``standoff`` [m] back along the axis (<= 0: some such torch may reach).

    The wrist centre is p - L z + (its offset across the axis, turned by the spin), L = standoff - p_TW's z; so
    it lies within L |z - z_R| + |p_TW across| <= 2 L sin(half_angle / 2) + |p_TW across| of p - L z_R, and
    within |standoff| + |p_TW| of p whatever the axis (the tighter of the two bounds holds)."""
    z = np.asarray(z_R, dtype=float)
    length = standoff - float(reach.p_TW[2])
    across = float(np.linalg.norm(reach.p_TW[:2]))
    slack = 2.0 * abs(length) * np.sin(min(half_angle, np.pi) / 2.0) + across
    p = np.atleast_2d(np.asarray(p_R, dtype=float))
    near, _ = reach.circle_distance(p - length * z)
    # whatever the axis: the wrist centre is within |p_TW| of the wire tip, itself ``standoff`` from p
    near_any, _ = reach.circle_distance(p)
    any_axis = near_any - abs(standoff) - float(np.linalg.norm(reach.p_TW))
    return np.maximum(near - slack, any_axis) - reach.d_max


def seam_beyond_reach(reach: ReachModel, p_start_R: npt.ArrayLike, p_end_R: npt.ArrayLike, step: float = 0.01) -> str:
    """Why a seam (its ends (3,) [m] in R) is beyond reach for every torch orientation, "" when some point of it
    may be reached: the first point along it (every ``step`` [m]) that is out of reach and by how much."""
    a, b = np.asarray(p_start_R, dtype=float), np.asarray(p_end_R, dtype=float)
    n = max(2, int(np.ceil(np.linalg.norm(b - a) / step)) + 1)
    s = np.linspace(0.0, 1.0, n)
    pts = a + np.outer(s, b - a)
    over = reach.point_excess(pts)
    bad = np.flatnonzero(over > 0.0)
    if len(bad) == 0:
        return ""
    k = int(bad[0])
    along = float(s[k] * np.linalg.norm(b - a))
    return (
        f"{along * 1000:.1f} mm along the seam lies {over[k] * 1000:.0f} mm beyond the arm's reach "
        f"(shoulder to wrist at most {reach.d_max * 1000:.0f} mm, torch {np.linalg.norm(reach.p_TW) * 1000:.0f} mm)"
    )


def seam_reach(reach: ReachModel, task: SeamTask, process: WeldProcess, step: float = 0.005) -> SeamFailure | None:
    """The pre-check of one seam (no IK): a BEYOND_REACH failure when some point of it (every ``step`` [m]) is
    out of the wrist's reach for every torch within the process's angles (its work angle and tolerance, its travel
    angle and tolerance, either direction, any spin), else None. The cone is about the torch axis at the nominal
    work angle and no travel angle; its half-angle is the work tolerance plus the travel angle and its tolerance."""
    d = task.p_end - task.p_start
    length = float(np.linalg.norm(d))
    t_b, n_b = fillet_axes(d, task.n_a, task.n_b)
    z0 = -(np.cos(process.work_angle) * t_b + np.sin(process.work_angle) * n_b)
    half = process.work_angle_tol + abs(process.travel_angle) + process.travel_angle_tol
    n = max(2, int(np.ceil(length / step)) + 1)
    s = np.linspace(0.0, length, n)
    pts = task.p_start + np.outer(s / max(length, 1e-12), d)
    over = cone_excess(reach, pts, z0, half, process.standoff)
    bad = np.flatnonzero(over > 0.0)
    if len(bad) == 0:
        return None
    k = int(bad[0])  # the first point out of reach, from the seam's start
    where = (
        f"beyond reach: at {s[k] * 1000:.1f} mm along the seam the wrist centre lies at least {over[k] * 1000:.0f} mm"
        f" beyond the shoulder's reach ({reach.d_max * 1000:.0f} mm) for every torch within the process's angles"
    )
    return SeamFailure(PlanReason.BEYOND_REACH, where, pts[k].copy(), -2e-3)
