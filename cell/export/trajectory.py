"""Joint trajectory export: JSON shaped like ROS ``trajectory_msgs/JointTrajectory`` and CSV, re-sampled from the plan
every ``dt`` plus every segment boundary (the format: docs/programs.md, "The joint trajectory")."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from cell.outputs import replacing, write_text
from cell.types.plan import WeldPlan
from cell.types.trajectory import Trajectory


def export_samples(plan: WeldPlan, dt: float | None = 0.004) -> tuple[Trajectory, np.ndarray]:
    """(trajectory, arc flags (n,) bool) re-sampled every dt [s] plus segment boundaries and the end."""
    traj, arc = plan.joint_trajectory()
    if dt is None:
        return traj, arc
    if not dt > 0.0:
        raise ValueError(f"export period dt must be positive or None, got {dt}")
    bounds = [s.t0 for s in plan.segments] + [plan.cycle_time]
    t = np.unique(np.concatenate([np.arange(0.0, traj.duration, dt), bounds]))
    t = t[(t >= 0.0) & (t <= traj.duration)]
    t = t[np.concatenate([[True], np.diff(t) > 1e-9])]
    q, qd, qdd = traj.sample(t)
    t[0] = 0.0
    return Trajectory(t, q, qd, qdd), plan.arc_at(t)


def _duration(t: float) -> dict[str, int]:
    sec = math.floor(t)
    nanosec = round((t - sec) * 1e9)
    if nanosec >= 1_000_000_000:
        sec, nanosec = sec + 1, nanosec - 1_000_000_000
    return {"sec": int(sec), "nanosec": nanosec}


def joint_trajectory_msg(
    traj: Trajectory, joint_names: tuple[str, ...] | list[str], frame_id: str = "base_link"
) -> dict[str, Any]:
    """A JSON-ready dict shaped like trajectory_msgs/JointTrajectory (times from the start of the plan)."""
    if len(joint_names) != traj.dof:
        raise ValueError(f"{len(joint_names)} joint names for a trajectory of {traj.dof} joints")

    # Rounded to 1e-9 rad by numpy, the whole table at once (Python's round differs in the last bit for about one
    # value in a million).
    q, qd, qdd = (np.round(a, 9).tolist() for a in (traj.q, traj.qd, traj.qdd))
    return {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": frame_id},
        "joint_names": list(joint_names),
        "points": [
            {
                "positions": q[i],
                "velocities": qd[i],
                "accelerations": qdd[i],
                "effort": [],
                "time_from_start": _duration(t),
            }
            for i, t in enumerate(traj.times.tolist())
        ],
    }


def write_json(plan: WeldPlan, path: str | Path, dt: float | None = 0.004) -> Path:
    """Write the plan's joint trajectory as JointTrajectory-shaped JSON, whole; the path written."""
    import json

    traj, _ = export_samples(plan, dt)
    text = json.dumps(joint_trajectory_msg(traj, plan.joint_names), separators=(",", ":"))
    return write_text(path, text, what="trajectory")


def write_csv(plan: WeldPlan, path: str | Path, dt: float | None = 0.004) -> Path:
    """Write ``t_s,q1_rad..qN_rad,arc_on`` rows, whole; the path written."""
    traj, arc = export_samples(plan, dt)
    header = ",".join(["t_s", *[f"q{i + 1}_rad" for i in range(traj.dof)], "arc_on"])
    table = np.column_stack([traj.times, traj.q, arc.astype(float)])
    fmt = ["%.6f"] + ["%.9f"] * traj.dof + ["%d"]
    p = Path(path)
    with replacing(p, what="trajectory") as tmp:
        np.savetxt(tmp, table, fmt=fmt, delimiter=",", header=header, comments="")
    return p
