"""Collisions: the robot against the obstacles and itself along every segment (conservative advancement, see
:mod:`cell.motion.collision`), when the gate has a checker."""

from __future__ import annotations

from dataclasses import dataclass

from cell.gate.base import GateInput, Violation, ViolationKind


@dataclass(frozen=True)
class Collisions:
    """Per segment: its first contact (none without a checker)."""

    def violations(self, gate: GateInput) -> list[Violation]:
        if gate.checker is None:
            return []
        out: list[Violation] = []
        for seg in gate.plan.segments:
            hit = gate.checker.check_trajectory(seg.trajectory, gate.plan.track)  # the base where E1 puts it
            if hit is not None:
                out.append(
                    Violation(
                        ViolationKind.COLLISION,
                        f"{hit.describe().split(' at t =')[0]} during the {seg.kind}"
                        f"{' of ' + seg.seam_id if seg.seam_id else ''}",
                        seg.t0 + hit.t,
                        "",
                        float(-hit.depth),
                    )
                )
        return out
