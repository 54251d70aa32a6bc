"""The welding program as values: seams to weld (:class:`SeamTask`) and the timed, checked plan (:class:`WeldPlan`)
with its segments and per-seam outcomes (:class:`SeamOutcome`, :class:`PlanReason`). Values only: no planning.
Frames: everything in the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import Literal

import numpy as np
import numpy.typing as npt

from cell.errors import PlanError
from cell.geometry import FloatArray, readonly
from cell.types.procedure import WeldProcedure
from cell.types.track import LinearTrack
from cell.types.trajectory import Trajectory

SegmentKind = Literal["move", "approach", "weld", "depart"]


@dataclass(frozen=True)
class SeamTask:
    """One seam to weld, in R: end points p_start, p_end (3,) [m] and the outward unit normals (3,) of the weld
    faces (n_a on the abutting part, n_b on the receiving part)."""

    id: str
    p_start: FloatArray
    p_end: FloatArray
    n_a: FloatArray
    n_b: FloatArray

    def __post_init__(self) -> None:
        for key in ("p_start", "p_end", "n_a", "n_b"):
            arr = readonly(getattr(self, key))
            if arr.shape != (3,) or not np.all(np.isfinite(arr)):
                raise ValueError(f"SeamTask {self.id}: {key} must be 3 finite values, got {arr.shape}")
            object.__setattr__(self, key, arr)

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.p_end - self.p_start))


@dataclass(frozen=True)
class Segment:
    """One motion of the plan. kind: move (PTP) | approach | weld | depart (LIN); t0 [s] its start in the plan;
    speed [m/s] the TCP speed of a LIN (0 for PTP); X_end (4, 4) the TCP pose at its end in R; arc_on: the arc
    burns during this segment (welds only: on at its start, off at its end, both at rest); procedure: the weld
    procedure a weld segment runs (None: the process defaults), pass_index: which of its passes (0: the root).
    zone_m [m]: the motion is approximated at its end (KRL ``C_DIS``, a RAPID zone): the next one starts when the
    TCP is this close to the programmed end, the joint target ``q_target`` (dof,) [rad] the trajectory then never
    reaches (0 and None: an exact stop there). link_s [s]: the first link_s of its trajectory is the blend from
    the previous motion (0: it starts at rest where the previous one ended). X_path (n, 4, 4): the planned TCP
    poses of a weld along a curve in R, start to end (None: a straight LIN to X_end), for the exporters'
    circular moves. e1_target [m]: the linear track's programmed E1 at an approximated end (None: where the
    trajectory ends)."""

    kind: SegmentKind
    seam_id: str
    trajectory: Trajectory
    t0: float
    X_end: FloatArray
    speed: float = 0.0
    arc_on: bool = False
    procedure: WeldProcedure | None = None
    pass_index: int = 0
    zone_m: float = 0.0
    q_target: FloatArray | None = None
    link_s: float = 0.0
    X_path: FloatArray | None = None
    e1_target: float | None = None

    @property
    def q_end(self) -> FloatArray:
        """(dof,) [rad] the programmed end: ``q_target`` when approximated, else where the trajectory ends."""
        return self.q_target if self.q_target is not None else self.trajectory.q[-1]

    @property
    def t1(self) -> float:
        return self.t0 + self.trajectory.duration

    @property
    def e1_end(self) -> float:
        """E1 [m] of the linear track at the segment's programmed end (0 without a track): ``e1_target`` when the
        motion is approximated there, else where the trajectory ends."""
        if self.e1_target is not None:
            return self.e1_target
        e1 = self.trajectory.e1
        return float(e1[-1]) if e1 is not None else 0.0


class PlanReason(StrEnum):
    """Why a seam could not be planned: the code of a :class:`SeamOutcome` (its ``reason`` gives the detail)."""

    BEYOND_REACH = "beyond_reach"  # a torch pose lies beyond the arm's reach bound (IK not even tried)
    IK_FAILED = "ik_failed"  # IK did not converge within tolerance and joint limits
    FLIP = "flip"  # a joint jumps between neighbouring IK knots (a configuration flip)
    SINGULAR = "singular"  # manipulability below the bound along a LIN
    COLLISION = "collision"  # the torch or the arm collides at the seam, on the approach or the depart
    TRANSFER_COLLISION = "transfer_collision"  # no collision-free transfer move to or from the seam
    TIMING = "timing"  # a line cannot be timed within the joint limits (e.g. the weld at the travel speed)
    NO_PROCEDURE = "no_procedure"  # no row of the WPS table fits the seam (joint type, position, leg)
    HOSE_WINDOW = "hose_window"  # A6 would leave the hose package's window of cable travel
    ENTERS_BODY = "enters_body"  # the TCP or the wire would enter a part's body (the safety gate)


@dataclass(frozen=True)
class Remainder:
    """A stretch of a curved seam its planned arcs leave for a manual weld: from ``from_m`` to ``to_m`` [m] along the
    located curve (a closed curve's ``to_m`` may pass its length: round its start), ``code`` what stops the arm
    there and ``why`` in words (no torch setting holds it, a restart whose overlap is short of the WPS's, an arc
    that failed its full solve). ``end``, for an arc refused after the search (the safety gate, a transfer): the
    end of the arc whose motions were at fault, ``start`` (the move into it, its approach) or ``end`` (its depart,
    the move on), the arc then planned again trimmed there; "" for its weld, or no arc."""

    from_m: float
    to_m: float
    code: PlanReason
    why: str
    end: str = ""

    @property
    def length_m(self) -> float:
        return self.to_m - self.from_m

    def describe(self) -> str:
        """One line: where along the curve, how long, why."""
        a, b = self.from_m * 1000.0, self.to_m * 1000.0
        return f"{a:.0f}-{b:.0f} mm along it ({b - a:.0f} mm, {self.code.value}: {self.why})"


@dataclass(frozen=True)
class SeamOutcome:
    """What became of one seam: feasible, or the reason and the failing point p_fail (3,) in R (empty if none).

    For a planned seam: reversed (welded from p_end to p_start), spin, work and travel angle [rad]. code: why it
    could not be planned (None when feasible); reason: the same in words, with where and by how much.
    trimmed : the length [m] not welded at the seam's table end (the torch's stand-off above the table,
    :mod:`cell.planning.stand_off`); 0 for a seam welded whole.
    remainder : a curved seam welded in part (``curve_remainder: manual``): the stretches its arcs leave for a
    manual weld (feasible: its arcs are planned; never welded whole); share : the part of it the arcs weld."""

    seam_id: str
    feasible: bool
    reason: str = ""
    p_fail: FloatArray = field(default_factory=lambda: np.zeros(0))
    reversed: bool = False
    spin: float = float("nan")
    work_angle: float = float("nan")
    travel_angle: float = float("nan")
    code: PlanReason | None = None
    trimmed: float = 0.0
    remainder: tuple[Remainder, ...] = ()
    share: float = 1.0

    @property
    def partial(self) -> bool:
        """A curved seam planned in part: its arcs weld what the arm reaches, the rest is left for a manual weld."""
        return self.feasible and bool(self.remainder)


@dataclass(frozen=True)
class ArcSpan:
    """One arc of a curved seam welded in several or in part (id ``<seam>#arcK``): its stretch from ``from_m`` to
    ``to_m`` [m] along the located curve (a closed curve's ``to_m`` may pass its length) and when it runs in the
    plan, from the start of the move into it to the end of its depart, ``t0`` to ``t1`` [s]."""

    arc_id: str
    from_m: float
    to_m: float
    t0: float
    t1: float


@dataclass(frozen=True)
class WeldPlan:
    """An ordered, timed welding program. segments: back to back (each starts where the previous ends, at rest);
    seams: one outcome per seam asked for, in input order; order: ids of the welded seams in welding order;
    planning_s: wall time spent planning [s]. track: the linear track the base rides on (None: a fixed base);
    then every segment's trajectory carries E1 (``Trajectory.e1``), and the poses (X_end) stay in R, the base at
    E1 = 0. arcs: the arcs of the curved seams welded in several or in part (their segments carry the seam's id),
    in time order."""

    joint_names: tuple[str, ...]
    q_home: FloatArray
    segments: tuple[Segment, ...]
    seams: tuple[SeamOutcome, ...]
    order: tuple[str, ...]
    planning_s: float = 0.0
    track: LinearTrack | None = None
    arcs: tuple[ArcSpan, ...] = ()

    @property
    def cycle_time(self) -> float:
        """Total duration [s] from home back to home."""
        return self.segments[-1].t1 if self.segments else 0.0

    @property
    def arc_time(self) -> float:
        return sum(s.trajectory.duration for s in self.segments if s.arc_on)

    def joint_ranges(self) -> dict[str, tuple[float, float]]:
        """Joint name -> (lowest, highest) value [rad] over the whole plan (how far A6 winds its hose package)."""
        if not self.segments:
            return {n: (float(q), float(q)) for n, q in zip(self.joint_names, self.q_home, strict=True)}
        q = np.vstack([s.trajectory.q for s in self.segments])
        return {n: (float(q[:, j].min()), float(q[:, j].max())) for j, n in enumerate(self.joint_names)}

    def outcome(self, seam_id: str) -> SeamOutcome:
        for o in self.seams:
            if o.seam_id == seam_id:
                return o
        raise KeyError(f"no seam {seam_id!r} in the plan; seams: {', '.join(o.seam_id for o in self.seams)}")

    def sample(self, t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(q, qd, qdd) (dof,) each at plan time t [s], clamped to [0, cycle_time]."""
        if not self.segments:
            z = np.zeros(len(self.joint_names))
            return np.array(self.q_home), z, z
        starts = np.array([s.t0 for s in self.segments])
        k = int(np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(starts) - 1))
        seg = self.segments[k]
        q, qd, qdd = seg.trajectory.sample(float(t) - seg.t0)
        return np.asarray(q), np.asarray(qd), np.asarray(qdd)

    def arc_at(self, times: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """(n,) whether the arc burns from each time to the next: on over [t0, t1) of every weld segment."""
        t = np.asarray(times, dtype=float)
        on = np.zeros(t.shape, dtype=bool)
        for s in self.segments:
            if s.arc_on:
                on |= (t >= s.t0 - 1e-9) & (t < s.t1 - 1e-9)
        return on

    def joint_trajectory(self) -> tuple[Trajectory, npt.NDArray[np.bool_]]:
        """The whole plan as one Trajectory (segments joined, shared boundary samples once) and the arc flag
        (n,) of each sample (holding until the next sample)."""
        if not self.segments:
            raise PlanError("the plan has no motion: no seam could be planned")
        parts_t, parts_q, parts_qd, parts_qdd = [], [], [], []
        for k, s in enumerate(self.segments):
            tr = s.trajectory
            sl = slice(0 if k == 0 else 1, None)
            parts_t.append(tr.times[sl] + s.t0)
            parts_q.append(tr.q[sl])
            parts_qd.append(tr.qd[sl])
            parts_qdd.append(tr.qdd[sl])
        times = np.concatenate(parts_t)
        times[0] = 0.0
        keep = np.concatenate([[True], np.diff(times) > 1e-12])  # zero-length segments add no sample
        e1 = None
        if any(s.trajectory.e1 is not None for s in self.segments):
            e1 = np.concatenate(
                [
                    (s.trajectory.e1 if s.trajectory.e1 is not None else np.zeros(len(s.trajectory.times)))[
                        0 if k == 0 else 1 :
                    ]
                    for k, s in enumerate(self.segments)
                ]
            )[keep]
        traj = Trajectory(
            times[keep],
            np.concatenate(parts_q)[keep],
            np.concatenate(parts_qd)[keep],
            np.concatenate(parts_qdd)[keep],
            e1,
        )
        return traj, self.arc_at(traj.times)


@dataclass(frozen=True)
class SeamProcedure:
    """The procedure a seam got: the row, the seam's joint type and position, whether its ends are swapped
    (``reverse``: welded from p_end to p_start, to weld a vertical seam upwards) and whether the direction is
    fixed (a vertical seam: the planner tries only that one)."""

    seam_id: str
    procedure: WeldProcedure
    joint: str
    position: str
    leg_mm: float
    reverse: bool = False
    fixed_direction: bool = False

    def oriented(self, task: SeamTask) -> SeamTask:
        """The task with its ends swapped when the procedure welds it the other way."""
        if not self.reverse:
            return task
        return SeamTask(task.id, task.p_end, task.p_start, task.n_a, task.n_b)


@dataclass(frozen=True)
class NoProcedure:
    """No row of the WPS table fits the seam: why (joint, position, leg it asked for)."""

    seam_id: str
    reason: str
