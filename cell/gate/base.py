"""The gate's vocabulary: what a violation is (:class:`Violation`, :class:`ViolationKind`), its options, what a
check sees (:class:`GateInput`) and the two shapes of a check (:class:`Check`, :class:`SegmentCheck`).

Units: SI (rad, rad/s, rad/s^2, rad/s^3, m, s) in the fields; degrees and mm in the messages.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Protocol

import numpy as np

from cell.config.motion import GateOptions
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.types import Part
from cell.types.gate import Violation as Violation  # the gate's vocabulary, kept in cell.types for the records
from cell.types.gate import ViolationKind as ViolationKind
from cell.types.plan import Segment, WeldPlan
from cell.types.trajectory import Trajectory

DEG = 180.0 / math.pi  # [deg/rad] for messages


def resample_times(times: FloatArray, rate_hz: float) -> FloatArray:
    """Times at least ``rate_hz`` apart-or-closer, keeping every stored sample (each interval of the stored
    trajectory is cut into equal parts no longer than 1 / rate_hz)."""
    h = np.diff(times)
    n_sub = np.maximum(np.ceil(h * rate_hz - 1e-6).astype(int), 1)
    start = np.repeat(times[:-1], n_sub)
    first = np.repeat(np.cumsum(n_sub) - n_sub, n_sub)  # index of each interval's first new time
    frac = (np.arange(int(n_sub.sum())) - first) / np.repeat(n_sub, n_sub)
    return np.append(start + np.repeat(h, n_sub) * frac, times[-1])


@dataclass(frozen=True)
class Resampled:
    """The whole plan re-sampled at the gate's rate: times t (m,) [s], q, qd, qdd (m, dof) and the jerk qddd
    (m - 1, dof), the finite difference of qdd, at t[1:]."""

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    qddd: FloatArray


@dataclass(frozen=True)
class GateInput:
    """What every check sees: the arm, the plan (with at least one segment), the arm's current state q_current
    (dof,) [rad], the collision checker (None: collisions are not checked) and the options; the parts' bodies in R
    no TCP or wire may enter (the aligned map's; empty: not checked), the wire's stick-out ``wire_m`` [m] behind
    the TCP, and per seam id the names of its joint's two parts (left out of that check along its own weld). The
    joined trajectory and its re-sampling are computed once, on first use."""

    robot: RobotModel
    plan: WeldPlan
    q_current: FloatArray
    checker: CollisionChecker | None
    options: GateOptions
    bodies: tuple[Part, ...] = ()
    wire_m: float = 0.0
    joint_parts: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    @cached_property
    def trajectory(self) -> Trajectory:
        """The plan as one trajectory (:meth:`WeldPlan.joint_trajectory`)."""
        return self.plan.joint_trajectory()[0]

    @cached_property
    def resampled(self) -> Resampled:
        t = resample_times(self.trajectory.times, self.options.rate_hz)
        q, qd, qdd = self.trajectory.sample(t)
        qddd = np.diff(qdd, axis=0) / np.diff(t)[:, None]
        return Resampled(t, q, qd, qdd, qddd)


class Check(Protocol):
    """One gate check: every violation of its kind in the plan, in a fixed order."""

    def violations(self, gate: GateInput) -> list[Violation]: ...


class SegmentCheck(Protocol):
    """A check that looks at one segment at a time (run by :class:`PerSegment`)."""

    def segment_violations(self, gate: GateInput, seg: Segment) -> list[Violation]: ...


@dataclass(frozen=True)
class PerSegment:
    """A :class:`Check` that runs its segment checks on every segment in turn (segment by segment, the checks in
    their order within each)."""

    checks: tuple[SegmentCheck, ...]

    def violations(self, gate: GateInput) -> list[Violation]:
        return [v for seg in gate.plan.segments for c in self.checks for v in c.segment_violations(gate, seg)]
