"""Singularities: along Cartesian (LIN) segments the manipulability stays above ``min_manipulability``
(joint-interpolated PTP moves may pass through singular poses harmlessly)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.gate.base import GateInput, Violation, ViolationKind
from cell.types.plan import Segment


@dataclass(frozen=True)
class Singularity:
    """Per LIN segment: its least manipulability, sampled every ``lin_step`` of TCP travel and at its end."""

    def segment_violations(self, gate: GateInput, seg: Segment) -> list[Violation]:
        opt, tr = gate.options, seg.trajectory
        if seg.kind != "move" and seg.speed > 0.0:
            step = seg.speed * max(float(np.min(np.diff(tr.times), initial=1.0)), 1e-6)  # [m] TCP travel per sample
            stride = max(1, int(opt.lin_step / step))
            idx = np.unique(np.append(np.arange(0, len(tr.times), stride), len(tr.times) - 1))
            m = np.array([gate.robot.manipulability(tr.q[i]) for i in idx])
            i = int(np.argmin(m))
            if m[i] < opt.min_manipulability:
                return [
                    Violation(
                        ViolationKind.SINGULARITY,
                        f"manipulability {m[i]:.3g} below {opt.min_manipulability:g} on the {seg.kind} of "
                        f"{seg.seam_id}",
                        seg.t0 + float(tr.times[idx[i]]),
                        "",
                        float(opt.min_manipulability - m[i]),
                    )
                ]
        return []
