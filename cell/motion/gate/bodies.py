"""Bodies: no motion takes the torch's wire tip (the TCP) or its wire into a part's body, what the collision model's
cut-back torch leaves out; a seam's own two parts are left out along its approach, weld and depart
(docs/reference.md section 7, docs/planning.md section 6). Frames: R; metres."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.motion.gate.base import GateInput, Violation, ViolationKind
from cell.motion.robot import RobotModel
from cell.types import Part
from cell.types.plan import Segment
from cell.types.trajectory import Trajectory

_COARSE = 33  # samples of a motion's TCP path that measure its length before the fine sampling
_WIRE_STEP = 0.0005  # [m] between the points along the wire: a 2.6 mm wall holds one deeper than 1 mm
_DEPTHS = (0.002, 0.003, 0.005, 0.01, 0.02, 0.05)  # [m] the depths a violation's excess is read from

Offset = Callable[[FloatArray], FloatArray]  # times (n,) [s] -> the base's offset (n, 3) [m] in R (a track's E1)


@dataclass(frozen=True)
class Entry:
    """Where a motion first enters a body: time t [s] within the motion, the body's name, how deep at least
    ``depth`` [m], the point p_R (3,) [m] and how far behind the TCP along the wire it lies ``behind_m`` (0: the
    TCP itself)."""

    t: float
    body: str
    depth: float
    p_R: FloatArray
    behind_m: float

    def describe(self) -> str:
        what = "the TCP" if self.behind_m == 0.0 else f"the wire {self.behind_m * 1000.0:.0f} mm behind the TCP"
        p_mm = np.round(self.p_R * 1000.0, 1).tolist()
        return f"{what} enters {self.body} ({self.depth * 1000.0:g} mm deep or more, p_R = {p_mm} mm)"


def _boxes(bodies: Sequence[Part], grow: float) -> tuple[FloatArray, FloatArray]:
    """The bodies' axis-aligned bounds in R grown by ``grow`` [m]: lo, hi (b, 3)."""
    v = [b.vertices() for b in bodies]
    return np.array([x.min(axis=0) for x in v]) - grow, np.array([x.max(axis=0) for x in v]) + grow


def _in_boxes(p: FloatArray, lo: FloatArray, hi: FloatArray) -> npt.NDArray[np.bool_]:
    """(n, b) whether each point (n, 3) lies within each bound."""
    return np.asarray(np.all((p[:, None, :] >= lo[None]) & (p[:, None, :] <= hi[None]), axis=2))


def path_points(
    robot: RobotModel,
    tr: Trajectory,
    step: float,
    offset: Offset | None = None,
    bounds: tuple[FloatArray, FloatArray] | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """A motion's TCP sampled every ``step`` [m] of travel or closer: times t (n,) [s], TCP positions p_R (n, 3)
    and torch axes z_R (n, 3) (unit, from the contact tip to the wire tip) in R, the base shifted by ``offset``.

    bounds : (lo, hi) (b, 3) [m] boxes in R: only the stretches of the motion whose coarse samples come within them
    (grown by twice the coarse samples' spacing) are sampled finely (none: the whole motion).
    """

    def poses(t: FloatArray) -> tuple[FloatArray, FloatArray]:
        if not len(t):
            return np.zeros((0, 3)), np.zeros((0, 3))
        q = tr.sample(t)[0]
        X = np.stack([robot.fk(qi) for qi in q])
        p = X[:, :3, 3] + (offset(t) if offset is not None else 0.0)
        return p, X[:, :3, 2]

    tc = np.linspace(0.0, tr.duration, _COARSE)
    pc, _ = poses(tc)
    chords = np.linalg.norm(np.diff(pc, axis=0), axis=1)
    # Uniform in time: twice the mean spacing's worth of samples holds the step where the TCP moves fastest.
    t = np.linspace(0.0, tr.duration, max(2, int(np.ceil(2.0 * float(chords.sum()) / step)) + 1))
    if bounds is not None:
        grow = 2.0 * float(chords.max(initial=0.0))
        near = _in_boxes(pc, bounds[0] - grow, bounds[1] + grow).any(axis=1)
        k = np.flatnonzero(near)
        # each near coarse sample keeps the fine samples out to its neighbours
        lo, hi = tc[np.maximum(k - 1, 0)], tc[np.minimum(k + 1, len(tc) - 1)]
        t = t[np.any((t[:, None] >= lo[None]) & (t[:, None] <= hi[None]), axis=1)]
    p, z = poses(t)
    return t, p, z


def body_entry(
    robot: RobotModel,
    tr: Trajectory,
    bodies: Sequence[Part],
    *,
    wire_m: float,
    depth: float,
    step: float,
    offset: Offset | None = None,
) -> Entry | None:
    """The first point of a motion's TCP or wire that lies inside one of ``bodies`` by more than ``depth`` [m]
    (None: it enters none), sampled every ``step`` [m] of TCP travel and every half mm along the wire's ``wire_m``."""
    if not bodies or tr.duration <= 0.0:
        return None
    lo, hi = _boxes(bodies, wire_m)
    t, p, z = path_points(robot, tr, step, offset, (lo, hi))
    if not len(t):
        return None
    k = int(np.ceil(wire_m / _WIRE_STEP)) + 1 if wire_m > 0.0 else 1
    s = np.linspace(0.0, wire_m, k)  # along the wire, back from its tip
    close = _in_boxes(p, lo, hi)  # (n, b): the TCP within a body's bounds grown by the wire
    for b, part in enumerate(bodies):
        poses = np.flatnonzero(close[:, b])
        if not poses.size:
            continue
        pts = (p[poses, None, :] - s[None, :, None] * z[poses, None, :]).reshape(-1, 3)
        inside = np.flatnonzero(np.asarray(part.contains(pts, margin=-depth), dtype=bool))
        if inside.size:
            deep = max(d for d in (depth, *_DEPTHS) if np.any(part.contains(pts[inside], margin=-d)))
            i, j = divmod(int(inside[0]), k)
            return Entry(float(t[poses[i]]), part.name, deep, pts[inside[0]].copy(), float(s[j]))
    return None


def seam_bodies(bodies: Sequence[Part], seg: Segment, joint_parts: Mapping[str, Sequence[str]]) -> list[Part]:
    """The bodies a segment is tested against: every one for a transfer, all but its seam's joint's two parts for
    its approach, weld and depart."""
    own = set(joint_parts.get(seg.seam_id, ())) if seg.kind != "move" else set()
    return [b for b in bodies if b.name not in own]


@dataclass(frozen=True)
class BodyEntry:
    """Per segment, the first body its TCP or wire enters deeper than ``body_depth`` (:func:`body_entry`), one
    violation per segment; none without bodies."""

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
