"""A curved seam welded in arcs, as a welder does on a fixed-arm cell where one go cannot weld it: the arcs (open
pieces of the curve, each started and stopped with its own crater, each restarting over the previous bead by the
process's overlap, the arm re-orienting between them in the air), their ids and what they cover
(docs/curves-welding.md sections 9 and 10; the arcs are chosen by :mod:`cell.planning.curves.arcs`).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from cell.geometry import FloatArray
from cell.planning.curves.path import _loop
from cell.planning.failures import SeamFailure
from cell.planning.seam_search import SeamSolution
from cell.types.curve_estimate import CurveEstimate
from cell.types.plan import Remainder

MAX_ARCS = 4  # a seam welded in more pieces than this is refused (each stop is a crater, each restart a defect risk)
# A seam welded in part (``curve_remainder: manual``) may take up to this many arcs: every stretch the arm cannot
# hold already stops an arc with its crater at its edge (pipe-flange: 3 gaps between 4 gussets, one arc between
# each two), so the bound is the whole cover's plus one more per such stop; beyond it the shortest arcs are left
# to the manual weld too (more restarts than that on one seam is a welder's job, not the robot's).
MAX_PARTIAL_ARCS = 2 * MAX_ARCS
ARC_MARK = "#arc"  # an arc's id: its seam's id, this mark and its number from 1


@dataclass(frozen=True)
class Split:
    """The arcs found for one curved seam: each arc's estimate (an open piece of the curve, id ``<seam>#arcK``) and
    solutions (one per pass), in weld order; ``share`` the part of the curve they cover (1: the whole seam);
    ``failure`` the search's word on the part no arc reaches (None when covered); ``remainder``: a seam welded in
    part, the stretches its arcs leave for a manual weld; ``spans``: each arc's id -> its (from, to) [m] along the
    located curve (a whole cover's too)."""

    arcs: tuple[tuple[CurveEstimate, tuple[SeamSolution, ...]], ...]
    share: float
    failure: SeamFailure | None
    remainder: tuple[Remainder, ...] = ()
    spans: tuple[tuple[str, float, float], ...] = ()

    @property
    def whole(self) -> bool:
        return self.failure is None and bool(self.arcs) and not self.remainder

    @property
    def partial(self) -> bool:
        return bool(self.arcs) and bool(self.remainder)


@dataclass(frozen=True)
class Partial:
    """A curved seam planned in part: its length [m] (``closed``: all round), the part its arcs weld (``share``),
    what they leave for a manual weld (``remainder``), each arc's stretch (``spans``: arc id -> (from, to) [m]
    along the curve) and the WPS's restart overlap [m] between its arcs (``overlap_m``; 0: an open curve's)."""

    length_m: float
    closed: bool
    share: float
    remainder: tuple[Remainder, ...]
    spans: dict[str, tuple[float, float]]
    overlap_m: float = 0.0


def arc_id(seam_id: str, k: int) -> str:
    """The id of a seam's k-th arc (from 1)."""
    return f"{seam_id}{ARC_MARK}{k}"


def seam_of(segment_id: str) -> str:
    """The seam an arc's id belongs to (any other id unchanged)."""
    return segment_id.split(ARC_MARK, 1)[0]


def sub_arc(est: CurveEstimate, s_a: float, s_b: float, k: int, step: float = 0.001) -> CurveEstimate:
    """The open piece of ``est`` from s_a to s_b [m] along its samples (a closed curve's taken round its start),
    sampled ``step`` [m] apart, with its normals and sigmas; its ends' sigma along it: the largest sample sigma
    (an arc's ends are where the plan puts them, not located ones)."""
    p, na, nb, s_k = _loop(est)
    sig = np.asarray(est.sigma_m)
    sig = np.concatenate([sig, sig[:1]]) if est.closed else sig
    sig = sig[: len(s_k)]
    total = float(s_k[-1])
    n = max(3, math.ceil((s_b - s_a) / step) + 1)
    u = np.linspace(s_a, s_b, n)
    u = np.mod(u, total) if est.closed else np.clip(u, 0.0, total)

    def at(v: FloatArray) -> FloatArray:
        return np.column_stack([np.interp(u, s_k, v[:, j]) for j in range(v.shape[1])])

    def unit(v: FloatArray) -> FloatArray:
        return np.asarray(v / np.linalg.norm(v, axis=1, keepdims=True))

    sigma = np.interp(u, s_k, sig)
    end = float(sigma.max())
    return replace(
        est,
        id=arc_id(est.id, k),
        p_RS=at(p),
        n_abutting_R=unit(at(na)),
        n_receiving_R=unit(at(nb)),
        closed=False,
        sigma_m=sigma,
        end_sigma_m=(end, end),
    )
