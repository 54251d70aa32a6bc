"""The ways a transfer may move between two configurations, tried in turn by :class:`cell.planning.transfers.Transfers`
(the first that is free is taken): a direct PTP, hops over via points, straight lifts, via home (docs/planning.md
section 1, docs/cycle.md). Frames: the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Protocol

from cell.config.motion import PlanOptions
from cell.geometry import FloatArray
from cell.motion.robot import RobotModel
from cell.motion.timing import ptp
from cell.planning.moves.pieces import Piece, TransferFail


class Mover(Protocol):
    """What a strategy asks of the transfers it serves (:class:`cell.planning.transfers.Transfers`): the arm, the
    plan's options, the lift height [m] in R, home (dof,) [rad], a pose raised, a vertical line and the first free
    way between two configurations."""

    robot: RobotModel
    opt: PlanOptions
    lift_z: float
    q_home: FloatArray

    def above(self, q: FloatArray, height: float) -> FloatArray | None: ...

    def vertical(self, q: FloatArray, height: float, up: bool) -> Piece | None: ...

    def midway(self, q_a: FloatArray, q_b: FloatArray, height: float) -> FloatArray: ...

    def search(self, q_a: FloatArray, q_b: FloatArray) -> list[Piece] | TransferFail: ...


class TransferStrategy(Protocol):
    """One way to move between two configurations; ``name`` is how failure messages call it."""

    @property
    def name(self) -> str: ...

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        """The motions q_a -> q_b (dof,) [rad]; raises IKError, TimingError or LineError when it cannot time
        them. Collisions are not checked here."""
        ...


@dataclass(frozen=True)
class Direct:
    """One PTP move."""

    name: str = "direct"

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        robot = mover.robot
        return [Piece("move", ptp(q_a, q_b, robot.limits, dt=mover.opt.dt), 0.0, robot.fk(q_b))]


@dataclass(frozen=True)
class Lift:
    """Straight up to the lift height (plus ``extra`` times ``transfer_lift``), PTP across, straight down."""

    name: str = "lift"
    extra: int = 0

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        robot, opt = mover.robot, mover.opt
        h = mover.lift_z + opt.transfer_lift * self.extra
        up = mover.vertical(q_a, h, up=True)
        down = mover.vertical(q_b, h, up=False)
        top_a = up.trajectory.q[-1] if up is not None else q_a
        top_b = down.trajectory.q[0] if down is not None else q_b
        pieces = [up] if up is not None else []
        pieces.append(Piece("move", ptp(top_a, top_b, robot.limits, dt=opt.dt), 0.0, robot.fk(top_b)))
        if down is not None:
            pieces.append(down)
        return pieces


@dataclass(frozen=True)
class Hop:
    """PTP up to a via point at the lift height above q_a's TCP, PTP across to one above q_b's, PTP down to q_b:
    the lift's via points reached by joint moves, faster than its straight lines where the collision check finds
    the joint path free. The lift height is ``transfer_lift`` (plus ``extra`` times it) above the highest
    obstacle, or ``rise`` [m] above it when given; ``over`` "start" or "end" keeps only that end's via point, "mid"
    takes one via point above the middle of the two ends instead (across a member between two seams)."""

    name: str = "hop"
    extra: int = 0
    rise: float | None = None
    over: str = "both"

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        robot, lim, dt = mover.robot, mover.robot.limits, mover.opt.dt
        top = mover.lift_z - mover.opt.transfer_lift
        h = top + self.rise if self.rise is not None else mover.lift_z + mover.opt.transfer_lift * self.extra
        if self.over == "mid":
            qs = [q_a, mover.midway(q_a, q_b, h), q_b]
        else:
            via_a = mover.above(q_a, h) if self.over != "end" else None
            via_b = mover.above(q_b, h) if self.over != "start" else None
            qs = [q_a, *(q for q in (via_a, via_b) if q is not None), q_b]
        return [Piece("move", ptp(a, b, lim, dt=dt), 0.0, robot.fk(b)) for a, b in itertools.pairwise(qs)]


@dataclass(frozen=True)
class ViaHome:
    """PTP to home, PTP on."""

    name: str = "home"

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        robot, lim, dt, home = mover.robot, mover.robot.limits, mover.opt.dt, mover.q_home
        return [
            Piece("move", ptp(q_a, home, lim, dt=dt), 0.0, robot.fk(home)),
            Piece("move", ptp(home, q_b, lim, dt=dt), 0.0, robot.fk(q_b)),
        ]


DEFAULT_STRATEGIES: tuple[TransferStrategy, ...] = (
    Direct(),
    Hop("hop_down", rise=0.02, over="end"),
    Hop("hop_up", rise=0.02, over="start"),
    Hop("hop_mid", rise=0.02, over="mid"),
    Hop("hop_low", rise=0.02),
    Hop(),
    Lift(),
    Hop("hop_high", extra=1),
    Lift("lift_high", extra=1),
    ViaHome(),
)
