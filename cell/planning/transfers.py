"""Transfers between seams and from/to home: a point-to-point move where the direct one is free, else lifted over the
obstacles or taken via home, each strategy also kept out of the bodies and the hose window (docs/planning.md
section 1). Frames: everything in the robot base frame R [m]; joints [rad]; time [s]."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cell.config.motion import GateOptions, PlanOptions
from cell.errors import IKError, MotionError, TimingError
from cell.geometry import FloatArray
from cell.motion.collision import CollisionChecker
from cell.motion.collision.wire import Entry, body_entry
from cell.motion.ik import solve_ik
from cell.motion.robot import RobotModel
from cell.motion.timing import Trajectory
from cell.motion.wrist import HoseWindow, nearest_wrist
from cell.planning.failures import LineError
from cell.planning.memo import TransferAnswers
from cell.planning.moves.lifts import DeepKnotError, vertical_line
from cell.planning.moves.pieces import Piece, TransferFail, joined, out_of_window
from cell.planning.moves.strategies import DEFAULT_STRATEGIES, Direct, Hop, Lift, TransferStrategy, ViaHome
from cell.planning.reach import ReachModel
from cell.process.torch import WeldProcess
from cell.types import Part

_BODY_STEP = 0.001  # [m] TCP travel between the body tests of a transfer (the gate tests it again, finer)
_NO_PLACE = np.full(3, np.nan)  # a failure's place not known (an error without one, a collision not located)
_COLLIDES = (False, "collides", _NO_PLACE)  # a motion known to collide, where not asked


class Transfers:
    """Collision-free transfers for one arm, process and scene (see the module docstring).

    obstacles : the parts and the table in R (the lift height is ``transfer_lift`` above the highest of them);
    q_home (dof,) [rad].
    """

    def __init__(
        self,
        robot: RobotModel,
        process: WeldProcess,
        checker: CollisionChecker,
        options: PlanOptions,
        obstacles: Sequence[Part],
        q_home: FloatArray,
        strategies: Sequence[TransferStrategy] = DEFAULT_STRATEGIES,
        answers: TransferAnswers | None = None,
    ) -> None:
        self.robot, self.process, self.checker, self.opt = robot, process, checker, options
        self.q_home = q_home
        self.strategies = tuple(strategies)
        self.window = HoseWindow(options.a6_center, options.a6_window)
        self.obstacles = tuple(obstacles)
        self._gate = GateOptions()
        tops = [float(np.max(o.vertices()[:, 2])) for o in obstacles]
        self.lift_z = (max(tops) if tops else 0.0) + options.transfer_lift
        # Each move searched once: the planner re-assembles its order after a failing transfer and asks again
        # for every transfer it kept (without this, n re-orderings cost n times the whole plan's transfers).
        self._memo: dict[tuple[bytes, bytes], list[Piece] | TransferFail] = {}
        self._between: dict[tuple[int, bytes], tuple[int, int, list[Piece]] | TransferFail] = {}
        # A search's attempts, each answered once: the order search, its screen and the shorter lines ask the same
        # strategy between the same ends again (None: not free), and a motion found not to run deep is not probed
        # again (the strategies share via points); ``answers``: kept from an earlier plan with this set-up.
        kept = answers if answers is not None and answers.fits(self) else TransferAnswers()
        self._pieces: dict[tuple[str, bytes, bytes, int], tuple[bool, str, FloatArray] | None] = kept.pieces
        self._above: dict[tuple[bytes, float], FloatArray | IKError] = kept.above
        self._vertical: dict[tuple[bytes, float, bool], Piece | Exception | None] = kept.vertical
        self._tried: dict[tuple[TransferStrategy, bytes, bytes], list[Piece] | None] = kept.tried
        self._shallow: set[tuple[str, bytes, bytes, int]] = kept.shallow
        self._probing = False
        self.retreats: tuple[TransferStrategy, ...] = ()
        self._retreat: set[bytes] = set()

    def retreat_from(self, qs: Sequence[FloatArray], ways: Sequence[TransferStrategy]) -> bool:
        """Try ``ways`` too (after every strategy) for the transfers out of the configurations ``qs`` (dof,) [rad]
        each: a seam's exits found at fault (every way out of them meets a part, whatever follows). False when
        they are tried already; the transfers searched so far are searched again (each strategy's answer kept)."""
        keys = {np.asarray(q, dtype=float).tobytes() for q in qs}
        if keys <= self._retreat:
            return False
        self._retreat |= keys
        self.retreats = tuple(dict.fromkeys((*self.retreats, *ways)))
        self._memo.clear()
        self._between.clear()
        return True

    def move(self, q_a: FloatArray, q_b: FloatArray) -> list[Piece] | TransferFail:
        """:meth:`search`, remembered per (q_a, q_b)."""
        key = (np.asarray(q_a, dtype=float).tobytes(), np.asarray(q_b, dtype=float).tobytes())
        if key not in self._memo:
            self._memo[key] = self.search(q_a, q_b)
        return self._memo[key]

    def search(self, q_a: FloatArray, q_b: FloatArray) -> list[Piece] | TransferFail:
        """The first strategy's motions q_a -> q_b that collide with nothing (zero-length ones left out); the
        last contact, or error, when every way collides."""
        found = self.between([q_a], [q_b])
        return found if isinstance(found, TransferFail) else found[2]

    def between(
        self, outs: Sequence[FloatArray], ins: Sequence[FloatArray]
    ) -> tuple[int, int, list[Piece]] | TransferFail:
        """The first strategy that finds free motions from one of ``outs`` to one of ``ins`` (dof,) [rad] each,
        both ordered nearest the welds first, the planned ends last: each strategy tries the pairs (outs[i],
        ins[i]) in turn (the shorter list's last repeated). (index into outs, index into ins, motions), or the
        last contact or error between the last two when every way collides (remembered per pair of lists; placed
        only when its reason or place is read)."""
        n = max(len(outs), len(ins))
        pairs = [(min(i, len(outs) - 1), min(i, len(ins) - 1)) for i in range(n)]
        key = (len(outs), b"".join(np.asarray(q, dtype=float).tobytes() for q in (*outs, *ins)))
        if key in self._between:
            return self._between[key]
        found: tuple[int, int, list[Piece]] | TransferFail | None = None
        out_of = [np.asarray(q, dtype=float).tobytes() in self._retreat for q in outs]
        for strategy in (*self.strategies, *(self.retreats if any(out_of) else ())):
            extra = strategy not in self.strategies
            for i, k in pairs:
                if extra and not out_of[i]:
                    continue
                got = self._tries(strategy, outs[i], ins[k])
                if got is not None:
                    found = (i, k, got)
                    break
            if found is not None:
                break
        last = pairs[-1]
        q_a, q_b = outs[last[0]], ins[last[1]]
        self._between[key] = found if found is not None else TransferFail.deferred(lambda: self._failure(q_a, q_b))
        return self._between[key]

    def _failure(self, q_a: FloatArray, q_b: FloatArray) -> TransferFail:
        """Why no strategy is free between the planned ends q_a, q_b: the last strategy's contact or error, an
        error having no place of its own keeping the last contact's before it (none: the origin). Only the
        attempts that say it are asked where they first collide (the search asked only whether they do)."""
        last: TransferFail | None = None
        for strategy in reversed(self.strategies):
            got = self._attempt(strategy, q_a, q_b, _NO_PLACE, exact=True)
            assert isinstance(got, TransferFail), "the search found every strategy collide"
            last = last or got
            if got.p_R is not _NO_PLACE:
                return TransferFail(last.reason, got.p_R)
        return TransferFail(last.reason if last is not None else "no collision-free way found", np.zeros(3))

    def _tries(self, strategy: TransferStrategy, q_a: FloatArray, q_b: FloatArray) -> list[Piece] | None:
        """:meth:`_attempt` where only whether the way is free matters: its motions, or None when it is not free;
        remembered per strategy and ends."""
        key = (strategy, np.asarray(q_a, dtype=float).tobytes(), np.asarray(q_b, dtype=float).tobytes())
        if key not in self._tried:
            got = self._attempt(strategy, q_a, q_b, _NO_PLACE, exact=False)
            self._tried[key] = None if isinstance(got, TransferFail) else got
        found = self._tried[key]
        return None if found is None else list(found)

    def _attempt(
        self, strategy: TransferStrategy, q_a: FloatArray, q_b: FloatArray, p_before: FloatArray, exact: bool = True
    ) -> list[Piece] | TransferFail:
        """One strategy's motions q_a -> q_b (zero-length ones left out) when they are free, else why not (an error
        that has no place keeps ``p_before`` (3,) [m], the last contact's). exact : False when only whether they
        are free matters (a collision's reason and place are then left unknown: :meth:`_blocked`)."""
        self._probing = not exact  # a lift's line may stop at a knot deep in a contact (its place not asked)
        try:
            pieces = strategy.pieces(self, q_a, q_b)
        except (IKError, TimingError, LineError) as exc:
            return TransferFail(f"{strategy.name}: {exc}", p_before)
        except DeepKnotError:
            return TransferFail(f"{strategy.name}: collides", _NO_PLACE)
        finally:
            self._probing = False
        wound = out_of_window(self.robot, self.window, pieces, q_a, q_b)
        if wound is not None:
            return TransferFail(f"{strategy.name}: {wound.reason}", wound.p_R)
        # Where only whether the way is free matters: a motion already known not to be free ends it before any
        # other is probed, then one that runs deep before any is checked in full.
        if not exact and any(self._pieces.get(_key(pc)) is not None for pc in pieces):
            return TransferFail(f"{strategy.name}: collides", _NO_PLACE)
        if not exact and any(self._runs_deep(pc) for pc in pieces):
            return TransferFail(f"{strategy.name}: collides", _NO_PLACE)
        for pc in pieces:
            blocked = self._blocked(pc, exact)
            if blocked is not None:
                wire, why, p_R = blocked
                return TransferFail(f"{strategy.name}: {why}" if wire else why, p_R)
        return [pc for pc in pieces if pc.trajectory.duration > 0.0]

    def _runs_deep(self, pc: Piece) -> bool:
        """Whether one motion is known not to be free, or runs deep into something
        (:meth:`CollisionChecker.deep_contact`: remembered as colliding, where unknown); False: it may be free."""
        key = _key(pc)
        if key not in self._pieces:
            if key in self._shallow:
                return False
            if self.checker.deep_contact(pc.trajectory.q) is None:
                self._shallow.add(key)
                return False
            self._pieces[key] = _COLLIDES
        return self._pieces[key] is not None

    def _blocked(self, pc: Piece, exact: bool = True) -> tuple[bool, str, FloatArray] | None:
        """Why one motion is not free: (the wire enters a body rather than a contact, the contact or entry in
        words, where p_R (3,) [m]); None when it is free. Remembered per motion (strategies share via points).
        exact : False when only whether it is free matters (a motion :meth:`_runs_deep` found colliding is not
        then asked where it first does)."""
        tr = pc.trajectory
        key = _key(pc)
        if key in self._pieces and (self._pieces[key] is not _COLLIDES or not exact):
            return self._pieces[key]
        hit = self.checker.check_path(tr.q, tr.times)
        entry = self._entry([pc]) if hit is None else None
        self._pieces[key] = (
            (False, hit.describe(), hit.p_R)
            if hit is not None
            else (True, entry.describe(), entry.p_R)
            if entry is not None
            else None
        )
        return self._pieces[key]

    def clear(self, tr: Trajectory) -> bool:
        """Whether a motion touches nothing (the collision model) and takes the wire into no obstacle's body."""
        if self.checker.collides(tr.q):
            return False
        return self._entry([Piece("move", tr, 0.0, self.robot.fk(tr.q[-1]))]) is None

    def _entry(self, pieces: list[Piece]) -> Entry | None:
        """Where the wire tip or the wire, which the collision model leaves out, first enters an obstacle's body
        along the motions (the safety gate's test, :mod:`cell.gate.bodies`); None: nowhere."""
        for pc in pieces:
            hit = body_entry(
                self.robot,
                pc.trajectory,
                self.obstacles,
                wire_m=self.process.stickout,
                depth=self._gate.body_depth,
                step=_BODY_STEP,
            )
            if hit is not None:
                return hit
        return None

    def above(self, q: FloatArray, height: float) -> FloatArray | None:
        """The configuration (dof,) [rad] with q's TCP pose raised to ``height`` [m] in R (IK seeded at q); None
        when q is already that high. Raises IKError when it cannot be reached (remembered too)."""
        X = self.robot.fk(q)
        if height - float(X[2, 3]) < 1e-3:
            return None
        X[2, 3] = height
        return self._ik((np.asarray(q, dtype=float).tobytes(), height), X, q)

    def midway(self, q_a: FloatArray, q_b: FloatArray, height: float) -> FloatArray:
        """The configuration (dof,) [rad] with the TCP above the middle of q_a's and q_b's TCPs at ``height`` [m]
        in R (at least as high as both), oriented as the joints' midpoint holds it (IK seeded there). Raises
        IKError when it cannot be reached (remembered too)."""
        q_mid = 0.5 * (np.asarray(q_a, dtype=float) + np.asarray(q_b, dtype=float))
        X = self.robot.fk(q_mid)
        p_a, p_b = self.robot.fk(q_a)[:3, 3], self.robot.fk(q_b)[:3, 3]
        X[:3, 3] = 0.5 * (p_a + p_b)
        X[2, 3] = max(height, float(p_a[2]), float(p_b[2]))
        return self._ik(
            (np.asarray(q_a, dtype=float).tobytes() + np.asarray(q_b, dtype=float).tobytes(), height), X, q_mid
        )

    def _ik(self, key: tuple[bytes, float], X: FloatArray, seed: FloatArray) -> FloatArray:
        """The IK solution (dof,) [rad] for pose X (4, 4) in R seeded at ``seed``, remembered under ``key`` (the
        ends it was asked from), a failure too; one whose A6 lies past the hose window is taken by whole turns
        (or the flipped wrist) back into it where the limits allow (:func:`nearest_wrist`: the same pose; a via
        point past the window fails every way through it). Raises the IKError remembered."""
        if key not in self._above:
            try:
                q = np.asarray(solve_ik(self.robot, X, seed, options=self.opt.ik))
                self._above[key] = nearest_wrist(self.robot, q, seed, self.window) if self.window.excess(q) else q
            except IKError as exc:
                self._above[key] = exc
        got = self._above[key]
        if isinstance(got, IKError):
            raise got.with_traceback(None)
        return got

    def vertical(self, q: FloatArray, height: float, up: bool) -> Piece | None:
        """A straight vertical TCP line between q's pose and the same pose at ``height`` [m] in R (None when q is
        already that high): up from q (a depart) or down to q (an approach). Remembered per (q, height, up), a
        failure too: a search tries the same line ends with every pair and strategy. While a search asks only
        whether a way is free, the line is probed (:class:`~cell.planning.moves.lifts.DeepKnotError`: its lift
        collides), and solved in full when asked otherwise."""
        key = (np.asarray(q, dtype=float).tobytes(), height, up)
        if key not in self._vertical or (isinstance(self._vertical[key], DeepKnotError) and not self._probing):
            probed = self.checker if self._probing else None
            try:
                self._vertical[key] = vertical_line(
                    self.robot, self.process, self.opt, self._reach_model(), q, height, up, probed
                )
            except (IKError, TimingError, LineError, DeepKnotError) as exc:
                self._vertical[key] = exc
        got = self._vertical[key]
        if isinstance(got, Exception):
            raise got.with_traceback(None)
        return got

    def _reach_model(self) -> ReachModel | None:
        """The arm's reach pre-check (built once, None for an arm it does not fit)."""
        if not hasattr(self, "_reach"):
            try:
                self._reach: ReachModel | None = ReachModel.from_robot(self.robot)
            except (ValueError, MotionError):
                self._reach = None
        return self._reach


def _key(pc: Piece) -> tuple[str, bytes, bytes, int]:
    """A motion's key among those remembered: its kind, ends and samples."""
    tr = pc.trajectory
    return pc.kind, tr.q[0].tobytes(), tr.q[-1].tobytes(), len(tr.times)


__all__ = [
    "DEFAULT_STRATEGIES",
    "Direct",
    "Hop",
    "Lift",
    "Piece",
    "TransferFail",
    "TransferStrategy",
    "Transfers",
    "ViaHome",
    "joined",
]
