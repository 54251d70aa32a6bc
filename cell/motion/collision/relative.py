"""How far the distances of the arm's shape pairs may fall for a joint step, per class of pairs: any arm point moves
at most sum |dq_j| r_j (r_j the farthest any shape lies from joint j's axis), which bounds how fast it nears an
obstacle; two of its own links move relative to each other only by the joints on the chain between them (in the
frame of the one nearer the base, the others move neither), so a self pair is bounded by those joints' terms alone.
Between a forearm and the wrist's links that is a small share of the whole arm's bound: the path check steps as
far as the obstacles allow where the wrist is folded near the forearm (docs/planning.md section 5)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray


@dataclass(frozen=True)
class RelativeBounds:
    """Per class of pairs, the weights of a joint step's bound [m/rad]: row 0 every joint's radius r (any arm point
    against an obstacle; the self pairs whose chain starts at the first joint); row c the radii of joints c + 1
    onwards, for the self pairs whose two links the joints from the (c + 1)-th on move apart (0 before it: a
    class's bound holds for every pair in it). ``order`` sorts the self pairs by class, ``starts`` where each
    class's run begins in that order."""

    weights: FloatArray
    order: npt.NDArray[np.intp]
    starts: npt.NDArray[np.intp]

    @classmethod
    def build(cls, parents: Sequence[int], radius: FloatArray, joints: Sequence[tuple[int, int]]) -> RelativeBounds:
        """From the kinematic tree (``parents`` of each joint id, 0 the fixed base), the joints' radii (dof,)
        [m/rad] (joint id j at j - 1) and each self pair's two parent joint ids (a serial arm: one chain)."""
        r = np.asarray(radius, dtype=float)
        first = [min(_chain(parents, a) ^ _chain(parents, b), default=1) for a, b in joints]
        weights = np.array([np.where(np.arange(len(r)) >= c, r, 0.0) for c in range(len(r))])
        cls_of = np.array([f - 1 for f in first], dtype=np.intp)  # joint id 1 (the whole arm): class 0
        order = np.argsort(cls_of, kind="stable")
        used = np.unique(cls_of)
        return cls(weights[[0, *(c for c in used if c > 0)]], order, np.searchsorted(cls_of[order], used))

    def motion(self, dq: npt.ArrayLike) -> FloatArray:
        """(classes,) [m]: the most any obstacle pair's distance, and each self class's, falls for a joint step dq
        (dof,) [rad] along a straight line in joint space."""
        return np.asarray(self.weights @ np.abs(np.asarray(dq, dtype=float)))

    def budgets(self, obstacle_m: float, self_m: FloatArray, cap_m: float) -> FloatArray:
        """(classes,) [m]: how far each class may move before the next check, from the least obstacle clearance
        (every arm point's motion, at most ``cap_m``) and each self pair's clearance ``self_m`` (n self pairs,)."""
        out = np.empty(len(self.weights))
        out[0] = min(obstacle_m, cap_m)
        if len(self_m):
            least = np.minimum.reduceat(np.asarray(self_m)[self.order], self.starts)  # per class, ascending
            k = len(least) - (len(out) - 1)  # 1: the first is class 0's (pairs the whole arm moves apart)
            if k:
                out[0] = min(out[0], float(least[0]))
            out[1:] = least[k:]
        else:
            out[1:] = np.inf
        return out


def _chain(parents: Sequence[int], joint: int) -> set[int]:
    """The joint ids from ``joint`` up to the base (0 not among them)."""
    out = set()
    while joint > 0:
        out.add(joint)
        joint = parents[joint]
    return out
