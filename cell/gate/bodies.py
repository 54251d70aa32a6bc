"""Bodies: no motion takes the torch's wire tip (the TCP) or its wire into a part's body, what the collision model's
cut-back torch leaves out (:func:`cell.motion.collision.wire.body_entry`); a seam's own two parts are left out along
its approach, weld and depart (docs/reference.md section 7, docs/planning.md section 6). Frames: R; metres."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from cell.gate.base import GateInput, Violation, ViolationKind
from cell.geometry import FloatArray
from cell.motion.collision.wire import body_entry
from cell.types import Part
from cell.types.plan import Segment


def seam_bodies(bodies: Sequence[Part], seg: Segment, joint_parts: Mapping[str, Sequence[str]]) -> list[Part]:
    """The bodies a segment is tested against: every one for a transfer, all but its seam's joint's two parts for
    its approach, weld and depart."""
    own = set(joint_parts.get(seg.seam_id, ())) if seg.kind != "move" else set()
    return [b for b in bodies if b.name not in own]


@dataclass(frozen=True)
class BodyEntry:
    """Per segment, the first body its TCP or wire enters deeper than ``body_depth``
    (:func:`cell.motion.collision.wire.body_entry`), one violation per segment; none without bodies."""

    def violations(self, gate: GateInput) -> list[Violation]:
        if not gate.bodies:
            return []
        out: list[Violation] = []
        for seg in gate.plan.segments:
            v = self.segment_violation(gate, seg)
            if v is not None:
                out.append(v)
        return out

    def segment_violation(self, gate: GateInput, seg: Segment) -> Violation | None:
        opt, tr, track = gate.options, seg.trajectory, gate.plan.track
        offset = None
        if track is not None:

            def offset(t: FloatArray) -> FloatArray:
                return np.stack([track.offset_R(float(e)) for e in tr.e1_at(t)])

        bodies = seam_bodies(gate.bodies, seg, gate.joint_parts)
        hit = body_entry(
            gate.robot, tr, bodies, wire_m=gate.wire_m, depth=opt.body_depth, step=opt.body_step, offset=offset
        )
        if hit is None:
            return None
        seam = f" of {seg.seam_id}" if seg.seam_id else ""
        return Violation(
            ViolationKind.BODY,
            f"{hit.describe()} during the {seg.kind}{seam}",
            seg.t0 + hit.t,
            "",
            hit.depth,
            seam_id=seg.seam_id,
            body=hit.body,
        )
