"""Start state: the plan starts at rest at the arm's current state (within ``start_tol``), inside the limits."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.gate.base import DEG, GateInput, Violation, ViolationKind


@dataclass(frozen=True)
class StartState:
    """Per joint: the plan's first sample off the current state, or not at rest; the current state outside the
    position limits."""

    def violations(self, gate: GateInput) -> list[Violation]:
        opt, names, traj = gate.options, gate.robot.joint_names, gate.trajectory
        out: list[Violation] = []
        q_cur = np.asarray(gate.q_current, dtype=float)
        off = np.abs(traj.q[0] - q_cur)
        for j in np.flatnonzero(off > opt.start_tol):
            out.append(
                Violation(
                    ViolationKind.START_STATE,
                    f"plan starts {off[j] * DEG:.3f} deg away from the current state",
                    0.0,
                    names[j],
                    float(off[j]),
                )
            )
        if not gate.robot.limits.contains(q_cur):
            out.append(Violation(ViolationKind.START_STATE, "the current state is outside the position limits", 0.0))
        for j in np.flatnonzero(np.abs(traj.qd[0]) > opt.rest_tol):
            out.append(
                Violation(
                    ViolationKind.START_STATE,
                    f"plan does not start at rest ({traj.qd[0, j] * DEG:.3g} deg/s)",
                    0.0,
                    names[j],
                    float(abs(traj.qd[0, j])),
                )
            )
        return out
