"""Arc switching: the arc burns only during weld segments, and is switched on and off at exact stops."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.gate.base import DEG, GateInput, Violation, ViolationKind
from cell.types.plan import Segment


@dataclass(frozen=True)
class ArcSwitching:
    """Per segment with the arc on: not a weld; not at rest (velocity or acceleration over ``rest_tol``) where
    the arc goes on, or where it goes off."""

    def segment_violations(self, gate: GateInput, seg: Segment) -> list[Violation]:
        if not seg.arc_on:
            return []
        out: list[Violation] = []
        if seg.kind != "weld":
            out.append(Violation(ViolationKind.ARC, f"arc on during a {seg.kind} segment", seg.t0))
        tr, rest = seg.trajectory, gate.options.rest_tol
        for end, at in (("on", 0), ("off", -1)):
            v = float(np.max(np.abs(tr.qd[at])))
            acc = float(np.max(np.abs(tr.qdd[at])))
            if v > rest or acc > rest:
                out.append(
                    Violation(
                        ViolationKind.ARC,
                        f"arc {end} while moving ({v * DEG:.3g} deg/s, {acc * DEG:.3g} "
                        f"deg/s^2) on {seg.seam_id}: needs an exact stop",
                        seg.t0 + float(tr.times[at]),
                        "",
                        max(v, acc),
                    )
                )
        return out
