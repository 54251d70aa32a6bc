"""A gap in the reach map walked afresh: the torch held at the middle of the gap by every setting IK finds from a
few seeds (the wrist flipped among them: the IK branches the map's walks, warm-started from where they began, do
not reach), then walked finer both ways from there (:mod:`.gapwalk`'s stations, steps and bounds) until it holds
the gap and the restart overlap past either side, a stretch of its own (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from cell.geometry import FloatArray, readonly
from cell.planning.curves.gapwalk import State, beam, fine_stations, merged, poser, walk
from cell.planning.curves.graph import refined
from cell.planning.curves.path import curve_path
from cell.planning.curves.reach import Run, _a46_fits, _fresh, settings
from cell.planning.seam_search import SeamSearch
from cell.process.torch_orientations import Candidate
from cell.types.curve_estimate import CurveEstimate

SEEDS = 2  # random IK seeds at a gap's middle, besides the arm's seed and its wrist flipped
HELD = 32  # the states at a gap's middle walked on from, at most


def seeded(
    search: SeamSearch,
    est: CurveEstimate,
    windows: Sequence[tuple[float, float]],
    flange: tuple[FloatArray, FloatArray] | None,
    q_seed: FloatArray,
    knot_m: float,
    overlap_m: float,
) -> list[Run]:
    """For each window (from, to) [m] along the located curve (those that overlap joined) and weld direction, the
    stretch walked from the window's middle both ways (:func:`.gapwalk.walk`) that reaches furthest: back at most
    ``overlap_m`` [m] past the window's start, on as far as it holds (a closed curve: at most all round and on by
    the overlap); from the states IK holds at the middle with every setting of
    the map and its gaps (:func:`.reach.settings`, :func:`.graph.refined`), seeded from ``q_seed`` (dof,) [rad],
    its wrist flipped and :data:`SEEDS` random ones."""
    total, closed = est.length_m, est.closed
    fine, bound = fine_stations(search, est, knot_m)
    rng = np.random.default_rng(11)
    flip = np.asarray(q_seed, dtype=float).copy()
    flip[[-3, -1]] += np.where(flip[[-3, -1]] > 0.0, -math.pi, math.pi)
    flip[-2] = -flip[-2]
    seeds = [q_seed, flip, *(search.robot.limits.sample(rng, 0.1) for _ in range(SEEDS))]
    every = settings(search, False) + settings(search, True) + refined(search)
    out: list[Run] = []
    for rev in sorted({c.reversed for c in every}):
        path = curve_path(est, fine, reverse=rev, overlap=2.0 * total if closed else 0.0)
        step = path.length / (len(path.s) - 1)
        pose = poser(path, search, flange)
        base = total if rev and not closed else 0.0  # located position = base + sign * length welded
        sign = -1.0 if rev else 1.0
        for lo, hi in merged(windows, total, closed):
            mid = 0.5 * (lo + hi)
            u = ((sign * mid) % total + total) if closed else min(total, max(0.0, sign * (mid - base)))
            k0 = round(u / step)
            on = math.ceil((total + overlap_m if closed else total) / step)  # on as far as it holds
            back = math.ceil((0.5 * (hi - lo) + overlap_m) / step)  # back past the window's start by the overlap
            held = _held(search, pose, k0, [c for c in every if c.reversed == rev], seeds)
            if not held:
                continue
            joined = {k0 + 1: held, k0 - 1: held}
            fwd = walk(search, pose, range(k0 + 1, min(len(path.s) - 1, k0 + on) + 1), joined, bound)
            bwd = walk(search, pose, range(k0 - 1, max(0, k0 - back) - 1, -1), joined, bound)
            got = _stretch(search, held, fwd, bwd, k0, rev, (base, sign, step), total, closed, total + overlap_m)
            if got is not None:
                out.append(got)
    return out


def _held(
    search: SeamSearch,
    pose: Callable[[int, tuple[float, float, float]], FloatArray],
    k: int,
    cands: Sequence[Candidate],
    seeds: Sequence[FloatArray],
) -> list[State]:
    """The states at fine station k: each setting of ``cands`` held by IK from each seed (clear, not singular),
    :func:`.gapwalk.beam`'s choice of at most :data:`HELD`, each its own root."""
    got: list[State] = []
    z = np.zeros(2)
    for c in cands:
        v = (c.spin, c.work_offset, c.travel_offset)
        X = pose(k, v)
        for sd in seeds:
            q = _fresh(search, X, [sd])
            if isinstance(q, np.ndarray):
                got.append(State(v, q, z, z, z, 0, 0))
    kept = beam(got, HELD)
    return [State(st.v, st.q, z, z, z, 0, -1 - i, i) for i, st in enumerate(kept)]


def _stretch(
    search: SeamSearch, held: list[State], fwd: list[list[State]], back: list[list[State]], k0: int, rev: bool,
    at: tuple[float, float, float], total: float, closed: bool, whole_m: float,
) -> Run | None:  # fmt: skip
    """The longest stretch through one of the ``held`` states at station k0: the furthest its root reaches back
    and on, A4's and A6's winding over both within their limits, a closed curve's cut to ``whole_m`` [m] at its
    start (``whole`` then); None where none holds past the middle."""
    base, sign, step = at

    def furthest(walked: list[list[State]], root: int) -> tuple[int, State | None]:
        for m in range(len(walked) - 1, -1, -1):
            for st in walked[m]:
                if st.root == root:
                    return m, st
        return -1, None

    best: tuple[int, int, State | None, int, State | None] | None = None
    for i in range(len(held)):
        mf, sf = furthest(fwd, i)
        mb, sb = furthest(back, i)
        spans = [s for s in (sf, sb) if s is not None]
        lo = np.min([s.lo for s in spans], axis=0) if spans else np.zeros(2)
        hi = np.max([s.hi for s in spans], axis=0) if spans else np.zeros(2)
        if not _a46_fits(search, *(hi - lo)):
            continue
        if best is None or mf + mb > best[0] + best[3]:
            best = (mf, i, sf, mb, sb)
    if best is None or best[0] + best[3] < 2:
        return None
    mf, i, _, mb, _ = best
    rows: list[tuple[int, State]] = [(k0, held[i])]
    for walked, m, d in ((fwd, mf, 1), (back, mb, -1)):
        chain = []
        if m >= 0:
            j = next(j for j, st in enumerate(walked[m]) if st.root == i)
            for mm in range(m, -1, -1):
                st = walked[mm][j]
                chain.append((k0 + d * (mm + 1), st))
                j = st.parent
        rows += chain
    rows.sort(key=lambda r: r[0])  # weld order
    if closed:
        rows = [r for r in rows if r[0] >= rows[-1][0] - math.floor(whole_m / step + 1e-9)]
    pos = np.array([base + sign * k * step for k, _ in rows])
    track = np.column_stack([pos, [st.v for _, st in rows]])
    q_track = np.array([st.q for _, st in rows])
    a, b = float(pos.min()), float(pos.max())
    lap = math.floor(a / total) * total if closed else 0.0
    order = np.argsort(pos)
    v0 = rows[0][1].v
    track = np.column_stack([track[order, 0] - lap, track[order, 1:]])
    q0 = rows[0][1].q
    whole = closed and b - a >= whole_m - step
    return Run(Candidate(rev, *v0), a - lap, b - lap, q0, whole, readonly(track), q_track=readonly(q_track[order]))
