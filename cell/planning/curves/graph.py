"""The reach map as a graph: nodes (station x torch setting) where IK holds the torch clear and not singular, edges
between one station and the next with the same setting, or the one after with a neighbouring setting (the torch
turned one spin step about its axis, or tilted between the nominal work/travel angles and an end of their
tolerance), where the joints move continuously; the longest paths through it are the stretches the cover takes,
each with the setting it holds at every station (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.interpolate import PchipInterpolator

from cell.geometry import FloatArray, readonly
from cell.planning.curves.path import curve_path, curve_poses
from cell.planning.curves.reach import (
    JUMP_FACTOR,
    MAX_JUMP,
    SPINS,
    STATION_SEEDS,
    Miss,
    Run,
    _a46_fits,
    _fresh,
    _next,
    settings,
    station_spacing,
)
from cell.planning.seam_search import SeamSearch
from cell.process.torch_orientations import Candidate
from cell.types.curve_estimate import CurveEstimate

SWITCH_STATIONS = 4  # a setting changes to a neighbouring one over this many stations (a spin step: 11 deg each)
EDGE_TRIES = 2  # where a setting's walk does not join a path, IK warm-started from at most this many paths' ends
EDGE_BUDGET = 64  # and at most this many such IK per station


def refined(search: SeamSearch) -> list[Candidate]:
    """The torch settings a gap in the map is walked with besides :func:`reach.settings`' (both directions x
    twice as many spins x the work and travel angles each nominal or at either end of their tolerance, the four
    corners included), none of those already walked."""
    pr = search.process
    spins = sorted({round(math.remainder(math.pi * k / SPINS, 2.0 * math.pi), 9) for k in range(2 * SPINS)})
    spins = [s for s in spins if abs(s) <= pr.spin_tol + 1e-9] or [0.0]
    w, t = pr.work_angle_tol, pr.travel_angle_tol
    angles = [(dw, dt) for dw in (0.0, w, -w) for dt in (0.0, t, -t)]
    directions = (False, True) if pr.reversible else (False,)
    done = set(settings(search, False) + settings(search, True))
    every = [Candidate(r, s, dw, dt) for dw, dt in angles for r in directions for s in spins]
    return [c for c in every if c not in done]


def _neighbours(cands: Sequence[Candidate], spin_loop: bool, w_tol: float, t_tol: float) -> list[list[int]]:
    """For each setting, the other settings a path may turn to from it: the same direction, and either the spin
    turned by at most one of :data:`SPINS` steps with the same angles, or the same spin with the work and travel
    angles each moved by at most its tolerance."""
    step = 2.0 * math.pi / SPINS + 1e-9
    out: list[list[int]] = []
    for i, a in enumerate(cands):
        nb = []
        for j, b in enumerate(cands):
            if j == i or b.reversed != a.reversed:
                continue
            turn = abs(math.remainder(b.spin - a.spin, 2.0 * math.pi)) if spin_loop else abs(b.spin - a.spin)
            dw, dt = abs(b.work_offset - a.work_offset), abs(b.travel_offset - a.travel_offset)
            turned = dw < 1e-9 and dt < 1e-9 and turn <= step
            tilted = turn < 1e-9 and dw <= w_tol + 1e-9 and dt <= t_tol + 1e-9
            if turned or tilted:
                nb.append(j)
        out.append(nb)
    return out


def _station_qs(
    search: SeamSearch, X: FloatArray, n: int, closed: bool, seeds: Sequence[FloatArray], max_step: float,
    at_m: FloatArray, misses: list[Miss],
) -> list[FloatArray | None]:  # fmt: skip
    """The joints holding X[k] (4, 4) at each of n stations: warm-started from the last station, afresh from
    ``seeds`` where that fails (IK, a jump beyond max_step [rad], a collision, singular); None (a :class:`Miss` at
    ``at_m[k]`` [m]) where no seed holds it. Then the stations no seed held, warm-started from their neighbour
    (a closed curve's on round its start, then back from each stretch's beginning)."""
    out: list[FloatArray | None] = []
    prev: FloatArray | None = None
    for k in range(n):
        q = _next(search, X[k], prev, max_step) if prev is not None else None
        if q is None:
            got = _fresh(search, X[k], seeds)
            if not isinstance(got, np.ndarray):
                misses.append(replace(got, at_m=float(at_m[k])))
            q = got if isinstance(got, np.ndarray) else None
        out.append(q)
        prev = q
    for k in range(n) if closed else []:  # on round the start, warm-started (no seed is needed there)
        before = out[k - 1]
        if out[k] is not None or before is None:
            break
        out[k] = _next(search, X[k], before, max_step)
    for k in range(2 * n - 1 if closed else n - 2, -1, -1):  # back into where each walk began
        after = out[(k + 1) % n]
        if out[k % n] is None and after is not None:
            out[k % n] = _next(search, X[k % n], after, max_step)
    return out


@dataclass
class _Node:
    start: int
    q: FloatArray
    wind: FloatArray  # A4's and A6's travel from the path's start, unwrapped (2,)
    lo: FloatArray
    hi: FloatArray
    switches: int
    pred: tuple[int, int] | None  # (station, setting) before it on its path


def _paths(
    search: SeamSearch, poses: list[FloatArray], qs: list[list[FloatArray | None]], nbrs: list[list[int]],
    closed: bool, whole_len: int, max_step: float, inside: FloatArray,
) -> dict[tuple[int, int], _Node]:  # fmt: skip
    """The longest paths through the graph of one weld direction (``qs[s][k]``: setting s's joints at station k
    as its walk found them, ``poses[s][k]`` its torch pose there), each node keeping the path from the earliest
    start that reaches it (then the fewest setting changes) with A4's and A6's winding within their limits; where
    ``inside`` (n,), a node its walk did not connect is solved again warm-started from the path before it (up to
    :data:`EDGE_TRIES` of them, :data:`EDGE_BUDGET` a station). A closed curve's stations are unrolled round its
    start (paths start in the first lap only, none runs longer than ``whole_len`` stations)."""
    n = len(inside)
    nodes: dict[tuple[int, int], _Node] = {}
    for t in range(n + whole_len if closed else n):
        alive, budget = False, EDGE_BUDGET
        for s, q_s in enumerate(qs):
            preds = []
            for t0, s0 in [(t - 1, s), *((t - SWITCH_STATIONS, j) for j in nbrs[s])]:
                p = nodes.get((t0, s0))
                if p is None or t - p.start > whole_len:
                    continue
                if any((k, s0) not in nodes and (k, s) not in nodes for k in range(t0 + 1, t)):
                    continue  # a turn over a station neither setting holds
                preds.append(((p.start, p.switches + (s0 != s)), t0, s0, p))
            preds.sort(key=lambda e: e[0])
            q = q_s[t % n]
            best = _best(search, q, preds, s, max_step) if q is not None else None
            if best is None and inside[t % n] and budget > 0:
                for _, t0, s0, p in preds[:EDGE_TRIES]:
                    budget -= 1
                    q_new = _next(search, poses[s][t % n], p.q, max_step)
                    best = _best(search, q_new, [(0, t0, s0, p)], s, max_step) if q_new is not None else None
                    if best is not None:
                        break
            if best is None and q is not None and t < n:
                z = np.zeros(2)
                best = _Node(t, q, z, z, z, 0, None)
            if best is not None:
                nodes[(t, s)] = best
                alive = True
        if t >= n and not alive and all((t - 1, s) not in nodes for s in range(len(qs))):
            break
    return nodes


def _best(search: SeamSearch, q: FloatArray, preds: list, s: int, max_step: float) -> _Node | None:
    """The node at joints q (dof,) of setting s on the first of ``preds`` (sorted, best first: (key, station,
    setting, node)) it follows with no joint stepping beyond max_step [rad] and A4/A6 within their winding."""
    for _, t0, s0, p in preds:
        step = np.angle(np.exp(1j * (q - p.q)))
        if float(np.abs(step).max()) > max_step:
            continue
        w = p.wind + step[[-3, -1]]
        lo, hi = np.minimum(p.lo, w), np.maximum(p.hi, w)
        if _a46_fits(search, *(hi - lo)):
            return _Node(p.start, q, w, lo, hi, p.switches + (s0 != s), (t0, s0))
    return None


def graph_map(
    search: SeamSearch,
    est: CurveEstimate,
    cands: Sequence[Candidate],
    flange: tuple[FloatArray, FloatArray] | None,
    q_seed: FloatArray,
    knot_m: float,
    overlap_m: float,
    memo: dict[Candidate, list[FloatArray | None]] | None = None,
    windows: Sequence[tuple[float, float]] = (),
) -> tuple[list[Run], list[Miss]]:
    """The stretches of ``est`` the torch holds along paths through the graph of ``cands`` (each setting walked
    along the stations once by warm-started IK: the nodes; the edges as the module says), the longest from each
    start, none inside another, each with its settings station by station (``Run.track``); and every station
    where a setting could not be held and why. ``memo``: each setting's joints at the stations, kept from one
    call to the next (a setting walked once); ``windows``: where along the located curve [m] (from, to) a node
    no walk joins to a path is solved from the path's end (IK warm-started), settings not yet walked reached only
    so (none: every setting walked, no such IK)."""
    spacing = station_spacing(est)
    max_step = min(MAX_JUMP, JUMP_FACTOR * search.opt.max_joint_step * max(1.0, spacing / knot_m))
    total = est.length_m
    rng = np.random.default_rng(7)
    seeds = [q_seed, *(search.robot.limits.sample(rng, 0.1) for _ in range(STATION_SEEDS))]
    spin_loop = search.process.spin_tol >= math.pi - 1e-9
    runs: list[Run] = []
    misses: list[Miss] = []
    for rev in sorted({c.reversed for c in cands}):
        group = [c for c in cands if c.reversed == rev]
        path = curve_path(est, spacing, reverse=rev)
        n = len(path.s) - 1 if est.closed else len(path.s)
        step = path.length / (len(path.s) - 1)
        at_m = np.mod(total - path.s, total) if rev else path.s
        memo = {} if memo is None else memo
        inside = np.ones(n, dtype=bool)
        if windows:
            inside[:] = False
            for lo, hi in windows:
                d = np.mod(at_m[:n] - lo, total) if est.closed else at_m[:n] - lo
                inside |= (d >= 0.0) & (d <= hi - lo)
        poses = [curve_poses(path, search.process, spin=c.spin, work_offset=c.work_offset,
                             travel_offset=c.travel_offset, flange=flange) for c in group]  # fmt: skip
        for c, X in zip(group, poses, strict=True):
            if c not in memo:  # in a window, a new setting is only reached from its neighbours' paths
                memo[c] = (
                    [None] * n if windows else _station_qs(search, X, n, est.closed, seeds, max_step, at_m, misses)
                )
        qs = [memo[c] for c in group]
        over = math.ceil(overlap_m / spacing) if est.closed else 0
        pr = search.process
        nbrs = _neighbours(group, spin_loop, pr.work_angle_tol, pr.travel_angle_tol)
        nodes = _paths(search, poses, qs, nbrs, est.closed, n + over, max_step, inside if windows else ~inside)
        runs += _runs(nodes, group, step, total, est.closed, rev, n + over)
    return runs, misses


def _runs(
    nodes: dict[tuple[int, int], _Node], group: Sequence[Candidate], step: float, total: float, closed: bool,
    rev: bool, whole_len: int,
) -> list[Run]:  # fmt: skip
    """The furthest-reaching paths from each start, one per setting they end in (the first found first, the
    others ``spare``: the cover falls back on them when it fails its full solve), those inside another start's
    dropped, as :class:`Run` (positions along the located curve's own order, the settings along it in
    ``track``)."""
    far: dict[int, int] = {}
    for (t, _), node in nodes.items():
        far[node.start] = max(t, far.get(node.start, -1))
    ends = sorted(  # each start's first found (the map's own choice) first
        (node.start, k, s) for k, ((t, s), node) in enumerate(nodes.items()) if t == far[node.start]
    )
    out: list[Run] = []
    reach, last = -1, -1
    for start, _, s in ends:
        t = far[start]
        if start != last and (t <= reach or t == start):
            continue
        reach, last = t, start
        chain: list[tuple[int, int]] = [(t, s)]
        while nodes[chain[-1]].pred is not None:
            chain.append(nodes[chain[-1]].pred)  # type: ignore[arg-type]
        chain.reverse()
        w = np.array([k * step for k, _ in chain])
        pos = total - w if rev else w
        vals = np.array([[group[j].spin, group[j].work_offset, group[j].travel_offset] for _, j in chain])
        vals[:, 0] = np.unwrap(vals[:, 0])
        lo_m, hi_m = start * step, t * step
        a, b = (total - hi_m, total - lo_m) if rev else (lo_m, hi_m)
        shift = math.floor(a / total) * total if closed else 0.0
        order = np.argsort(pos)
        track = np.column_stack([pos[order] - shift, vals[order]])
        first = group[chain[0][1]]
        q0 = nodes[chain[0]].q
        spare = bool(out) and out[-1].a_m == a - shift and out[-1].b_m == b - shift
        q_track = readonly(np.array([nodes[c].q for c in chain])[order])
        whole = t - start >= whole_len
        out.append(Run(first, a - shift, b - shift, q0, whole, readonly(track), spare=spare, q_track=q_track))
    return out


def settings_along(run: Run, at_m: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The torch's spin, work and travel offsets [rad] (each (n,)) at the located-curve positions at_m (n,) [m] of
    ``run`` (a lap on from its track by ``run.origin_m``): a monotone C1 interpolation through its stations'
    settings, held at the ends; its one setting where it has no track."""
    x = np.asarray(at_m, dtype=float)
    c = run.cand
    if run.track is None or len(run.track) < 2:
        one = np.ones(len(x))
        return c.spin * one, c.work_offset * one, c.travel_offset * one
    tr = np.asarray(run.track)
    u = np.clip(x - run.origin_m, tr[0, 0], tr[-1, 0])
    f = PchipInterpolator(tr[:, 0], tr[:, 1:], axis=0)
    v = f(u)
    return v[:, 0], v[:, 1], v[:, 2]


def gaps(runs: Sequence[Run], total: float, closed: bool, margin: float) -> list[tuple[float, float]]:
    """The stretches of a curve ``total`` [m] long that no run holds, each widened by ``margin`` [m] either side
    (from, to) [m] along the located curve."""
    bins = np.zeros(max(1, math.ceil(total / 0.001)), dtype=bool)
    for r in runs:
        idx = np.arange(math.floor(r.a_m / 0.001), math.ceil(r.b_m / 0.001))
        bins[np.mod(idx, len(bins)) if closed else idx[(idx >= 0) & (idx < len(bins))]] = True
    if bins.all():
        return []
    free = ~bins
    shift = int(np.argmax(bins)) if closed and free[0] and free[-1] else 0  # a gap across the start: scan from
    free = np.roll(free, -shift)  # where it is held
    edges = np.flatnonzero(np.diff(np.concatenate([[0], free.astype(int), [0]])))
    return [
        ((a + shift) * 0.001 - margin, (b + shift) * 0.001 + margin)
        for a, b in zip(edges[::2], edges[1::2], strict=True)
    ]
