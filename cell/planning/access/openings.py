"""A transfer for a seam inside an opening (a frame's inside corner, the part stood up on a positioner) where the
general ones (direct, hops, lifts, home) meet the part: the torch steps out of the opening towards the arm, square
to its axis and its orientation kept (the side a positioner's pose leaves open faces the arm), rises in front of the
part towards the lift height, and comes down and in to the next seam the same way (docs/positioner.md, "Ways in and
out"). Frames: R [m]; joints [rad]; time [s]."""

from __future__ import annotations

import itertools
import weakref
from dataclasses import dataclass

import numpy as np

from cell.errors import IKError
from cell.geometry import FloatArray
from cell.motion.ik import solve_ik
from cell.motion.timing import ptp
from cell.planning.moves.pieces import Piece
from cell.planning.moves.strategies import DEFAULT_STRATEGIES, Mover, TransferStrategy

IN_M = 0.10  # [m] how far aside the torch comes in to a seam
OUT_M = 0.15  # [m] how far aside it steps out of one
RISE_STEP_M = 0.05  # [m] the rise's IK is walked up in steps this long (it keeps the arm's branch)


@dataclass(frozen=True)
class Aside:
    """PTP moves through via points: ``out_m`` from q_a's TCP towards the arm's shoulder, square to its torch axis,
    then that pose raised to the lift height; across; and the same for q_b (``in_m``) in reverse. A distance of 0
    leaves that end by a PTP move from where it is."""

    name: str = "aside"
    out_m: float = OUT_M
    in_m: float = IN_M

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        qs = [q_a, *_vias_of(mover, q_a, self.out_m), *_vias_of(mover, q_b, self.in_m)[::-1], q_b]
        robot, lim, dt = mover.robot, mover.robot.limits, mover.opt.dt
        return [Piece("move", ptp(a, b, lim, dt=dt), 0.0, robot.fk(b)) for a, b in itertools.pairwise(qs)]


# The via points of each configuration and distance, per transfer search (the strategies share them: an end's
# "out" serves its "out" and both "both" ways); gone with the search.
_VIAS: weakref.WeakKeyDictionary[Mover, dict[tuple[bytes, float], list[FloatArray] | IKError]] = (
    weakref.WeakKeyDictionary()
)


def _vias_of(mover: Mover, q: FloatArray, aside_m: float, rise: bool = True) -> list[FloatArray]:
    """:func:`_vias`, remembered per mover, configuration, distance and ``rise`` (an IKError too)."""
    memo = _VIAS.setdefault(mover, {})
    key = (np.asarray(q, dtype=float).tobytes(), aside_m if rise else -aside_m)
    if key not in memo:
        try:
            memo[key] = _vias(mover, q, aside_m, rise)
        except IKError as exc:
            memo[key] = exc
    got = memo[key]
    if isinstance(got, IKError):
        raise got
    return got


def _vias(mover: Mover, q: FloatArray, aside_m: float, rise: bool = True) -> list[FloatArray]:
    """The via points (dof,) [rad] out of q: ``aside_m`` towards the shoulder square to the torch axis, then (with
    ``rise``) that pose raised towards the lift height, as high as the arm reaches it (IK seeded at q and walked
    up); none when ``aside_m`` is 0. Raises IKError when the first cannot be reached."""
    if aside_m <= 0.0:
        return []
    robot, ik = mover.robot, mover.opt.ik
    X = robot.fk(q)
    centre, _ = robot.reach_bound("torch_tcp")
    z = X[:3, 2]
    v = np.asarray(centre, dtype=float) - X[:3, 3]
    v = v - (v @ z) * z
    X[:3, 3] += aside_m * v / max(float(np.linalg.norm(v)), 1e-9)
    out = [np.asarray(solve_ik(robot, X, q, options=ik))]
    z0 = float(X[2, 3])
    if mover.lift_z - z0 < 1e-3 or not rise:
        return out
    q_up = out[0]
    for h in [*np.arange(z0 + RISE_STEP_M, mover.lift_z, RISE_STEP_M), mover.lift_z]:
        X[2, 3] = h
        try:
            q_up = np.asarray(solve_ik(robot, X, q_up, options=ik))
        except IKError:  # the arm reaches no higher with this orientation: the rise stops where it could
            break
    return out if q_up is out[0] else [*out, q_up]


@dataclass(frozen=True)
class Retreat:
    """A way out of a seam whose every other way meets a part on the arm's first turn (an arm reaching under one
    rail to the next: the forearm rises into the upper one): a PTP move to a via point ``out_m`` from q_a's TCP
    towards the arm's shoulder, square to its torch axis and its orientation kept (the forearm drawn back from
    under what is above it), then (``home``: a PTP move home first) on to q_b the first way the transfers find
    from there (a PTP move where none does)."""

    name: str = "retreat"
    out_m: float = 0.35
    home: bool = False

    def pieces(self, mover: Mover, q_a: FloatArray, q_b: FloatArray) -> list[Piece]:
        (via,) = _vias_of(mover, q_a, self.out_m, rise=False)
        robot, lim, dt = mover.robot, mover.robot.limits, mover.opt.dt
        stops = [q_a, via, *([mover.q_home] if self.home else [])]
        out = [Piece("move", ptp(a, b, lim, dt=dt), 0.0, robot.fk(b)) for a, b in itertools.pairwise(stops)]
        on = mover.search(stops[-1], q_b)
        return [
            *out,
            *(on if isinstance(on, list) else [Piece("move", ptp(stops[-1], q_b, lim, dt=dt), 0.0, robot.fk(q_b))]),
        ]


# The ways out of an exit found at fault (:meth:`cell.planning.transfers.Transfers.retreat_from`), after WAYS: the
# located railing's POST_L bottom fillet (reaching under the top rail) is left 350 mm back, not 250; from there, or
# from home, on the transfers' own ways.
RETREATS: tuple[TransferStrategy, ...] = tuple(
    Retreat(f"retreat_{d * 1000:.0f}{'_home' if home else ''}", d, home)
    for home in (False, True)
    for d in (0.25, 0.35, 0.45)
)


def opening_ways() -> tuple[Aside, ...]:
    """The ways out of and into an opening, the planner's last strategies (:data:`WAYS`: where the direct, hop, lift
    and home ways all meet the part): in at the seam's end only, out at its start only, then both. One distance
    each way, those that served fence1-positioner's inside corners (docs/positioner.md, "Ways in and out")."""
    return Aside("aside_in", 0.0, IN_M), Aside("aside_out", OUT_M, 0.0), Aside("aside", OUT_M, IN_M)


WAYS: tuple[TransferStrategy, ...] = (*DEFAULT_STRATEGIES, *opening_ways())  # the planner's transfers, in order
