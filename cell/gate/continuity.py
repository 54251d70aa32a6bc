"""Continuity: consecutive segments meet (same time, same configuration), and no stored sample jumps further
than the velocity limit allows over its interval."""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from cell.gate.base import DEG, GateInput, Violation, ViolationKind


@dataclass(frozen=True)
class SegmentJoins:
    """Per pair of consecutive segments that do not meet: the joint with the largest gap."""

    def violations(self, gate: GateInput) -> list[Violation]:
        names, segs = gate.robot.joint_names, gate.plan.segments
        out: list[Violation] = []
        for s0, s1 in pairwise(segs):
            gap = np.abs(s0.trajectory.q[-1] - s1.trajectory.q[0])
            if abs(s0.t1 - s1.t0) > 1e-9 or gap.max() > 1e-9:
                jg = int(np.argmax(gap))
                out.append(
                    Violation(
                        ViolationKind.JUMP,
                        f"segments do not meet: {gap[jg] * DEG:.3f} deg, {abs(s0.t1 - s1.t0):.3g} "
                        f"s apart ({s0.kind} -> {s1.kind} of {s1.seam_id or 'home'})",
                        s1.t0,
                        names[jg],
                        float(gap[jg]),
                    )
                )
        return out


@dataclass(frozen=True)
class SampleJumps:
    """Per joint: the stored step that exceeds the velocity limit (with ``rel_tol``) over its interval most."""

    def violations(self, gate: GateInput) -> list[Violation]:
        lim, names, traj = gate.robot.limits, gate.robot.joint_names, gate.trajectory
        h = np.diff(traj.times)[:, None]
        step = np.abs(np.diff(traj.q, axis=0))
        allowed = lim.v_max * h * (1.0 + gate.options.rel_tol) + 1e-9
        bad = step > allowed
        out: list[Violation] = []
        for j in np.flatnonzero(bad.any(axis=0)):
            i = int(np.argmax(step[:, j] - allowed[:, j]))
            out.append(
                Violation(
                    ViolationKind.JUMP,
                    f"moves {step[i, j] * DEG:.3f} deg in {h[i, 0] * 1000:.1f} ms (at most "
                    f"{allowed[i, j] * DEG:.3f} deg at full speed)",
                    float(traj.times[i + 1]),
                    names[j],
                    float(step[i, j] - allowed[i, j]),
                )
            )
        return out
