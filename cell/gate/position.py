"""Position limits at every sample of the plan re-sampled at ``rate_hz``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.gate.base import DEG, GateInput, Violation, ViolationKind


@dataclass(frozen=True)
class PositionLimits:
    """Per joint: the sample furthest outside [q_min, q_max]."""

    def violations(self, gate: GateInput) -> list[Violation]:
        lim, names, rs = gate.robot.limits, gate.robot.joint_names, gate.resampled
        q = rs.q
        pos = np.maximum(lim.q_min - q, q - lim.q_max)
        out: list[Violation] = []
        for j in np.flatnonzero(np.any(pos > 1e-9, axis=0)):
            i = int(np.argmax(pos[:, j]))
            out.append(
                Violation(
                    ViolationKind.POSITION,
                    f"{q[i, j] * DEG:.3f} deg is {pos[i, j] * DEG:.3g} deg outside "
                    f"[{lim.q_min[j] * DEG:.1f}, {lim.q_max[j] * DEG:.1f}] deg",
                    float(rs.t[i]),
                    names[j],
                    float(pos[i, j]),
                )
            )
        return out
