"""The reach map's gaps walked finer: a stretch that gives out in a gap walked again from its start at stations a
third of the map's apart (no further apart than the knots) and on through the gap, the torch's setting free to turn
and tilt a small step at every station (off the map's grid), several IK branches kept per station and setting,
every step held to the knots' flip bound scaled to the stations' spacing (not the map's three times it) and A4's
and A6's winding to their limits and the hose window (docs/curves-welding.md section 10).

Frames: everything in the robot base frame R [m]; joints [rad]."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from cell.geometry import FloatArray, readonly
from cell.planning.curves.path import CurvePath, curve_path, curve_poses
from cell.planning.curves.reach import Run, _a46_fits, _next, station_spacing
from cell.planning.seam_search import SeamSearch
from cell.types.curve_estimate import CurveEstimate

FINE = 3  # the gap walk's stations this many times closer than the map's (and no further apart than the knots)
SPIN_STEP = math.radians(11.25)  # [rad] the torch turned about its axis by at most this much a station
TILT_STEP = math.radians(5.0)  # [rad] or its work or travel angle tilted by at most this much (within tolerance)
BEAM = 16  # states (setting x IK branch) kept per station, the fewest setting changes first
PER_SETTING = 2  # of them at most this many IK branches of one setting
RUNS_EACH = 2  # the longest this many stretches of each weld direction giving out in a gap are carried on


@dataclass(frozen=True)
class State:
    v: tuple[float, float, float]  # the torch's spin, work and travel offsets [rad]
    q: FloatArray
    wind: FloatArray  # A4's and A6's travel from the stretch's start, unwrapped (2,); and its extremes so far
    lo: FloatArray
    hi: FloatArray
    changes: int
    parent: int  # its state's index at the station before; -1 - j: started at the j-th of its stretch or seeds
    root: int = 0  # the seed it grew from (a seeded walk)


def walked(
    search: SeamSearch,
    est: CurveEstimate,
    runs: Sequence[Run],
    windows: Sequence[tuple[float, float]],
    flange: tuple[FloatArray, FloatArray] | None,
    knot_m: float,
    overlap_m: float,
) -> list[Run]:
    """The longest stretches (:data:`RUNS_EACH` of each weld direction) whose weld gives out inside one of
    ``windows`` (from, to) [m] along the located curve, each walked again by :func:`_carried` as far as the walk
    holds, at most to the window's far end and ``overlap_m`` [m] on (a closed curve: at most until it holds all
    round and on by the overlap); those the walk holds past where they gave out."""
    total, closed = est.length_m, est.closed
    fine, bound = fine_stations(search, est, knot_m)
    windows = merged(windows, total, closed)
    out: list[Run] = []
    for rev in (False, True):
        path = curve_path(est, fine, reverse=rev, overlap=2.0 * total if closed else 0.0)
        ends = []
        for r in sorted((r for r in runs if r.cand.reversed == rev and r.q_track is not None), key=lambda r: -r.length):
            end = r.a_m if rev else r.b_m
            win = next((w for w in windows if inside(end, w, total, closed)), None)
            if win is not None and not (closed and r.whole):
                ends.append((r, win))
        for r, (lo, hi) in ends[:RUNS_EACH]:
            left = (r.a_m - lo if rev else hi - r.b_m) % total if closed else (r.a_m - lo if rev else hi - r.b_m)
            reach = left + overlap_m
            if closed:
                reach = min(reach, total + overlap_m - r.length)
            got = _carried(search, est, path, r, reach, bound, flange, total + overlap_m)
            if got is not None:
                out.append(got)
    return out


def fine_stations(search: SeamSearch, est: CurveEstimate, knot_m: float) -> tuple[float, float]:
    """The gap walk's station spacing along ``est`` [m] (:data:`FINE` times closer than the map's, no further apart
    than the knots ``knot_m``) and the largest joint step between two stations [rad]: the knots' flip bound
    scaled to that spacing."""
    fine = min(station_spacing(est) / FINE, knot_m)
    return fine, search.opt.max_joint_step * fine / knot_m


def merged(windows: Sequence[tuple[float, float]], total: float, closed: bool) -> list[tuple[float, float]]:
    """The windows, those that overlap joined into one."""
    out: list[tuple[float, float]] = []
    for lo, hi in sorted(windows):
        if out and lo <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], hi))
        else:
            out.append((lo, hi))
    if closed and len(out) > 1 and out[-1][1] - total >= out[0][0]:  # round the start
        out = [(out[-1][0], max(out[-1][1], out[0][1] + total)), *out[1:-1]]
    return out


def inside(x: float, window: tuple[float, float], total: float, closed: bool) -> bool:
    lo, hi = window
    return 0.0 <= ((x - lo) % total if closed else x - lo) <= hi - lo


def _carried(
    search: SeamSearch,
    est: CurveEstimate,
    path: CurvePath,
    run: Run,
    reach_m: float,
    bound: float,
    flange: tuple[FloatArray, FloatArray] | None,
    whole_m: float,
) -> Run | None:
    """``run`` walked again from its start along ``path`` (the curve at the fine stations in its weld direction,
    from the located curve's start; a closed one three laps) and on past where its weld gives out by at most
    ``reach_m`` [m]: a beam of states (a setting and the joints holding it) from its first station's, each station
    every state's setting held, turned by :data:`SPIN_STEP` or tilted by :data:`TILT_STEP` and solved by IK
    warm-started from it, kept where no joint steps beyond ``bound`` [rad], the arm is clear and not singular and
    A4's and A6's winding fits. The furthest-reaching state's path, as a longer :class:`Run` (``whole`` once it
    is ``whole_m`` [m] long); None where the walk gains nothing."""
    assert run.track is not None and run.q_track is not None
    total, closed, rev = est.length_m, est.closed, run.cand.reversed
    order = np.argsort(run.track[:, 0])[::-1] if rev else np.argsort(run.track[:, 0])
    rows, qs = np.asarray(run.track)[order], np.asarray(run.q_track)[order]  # in weld order
    pos0 = rows[-1, 0]
    sign = -1.0 if rev else 1.0

    def u_of(p: float) -> float:  # the fine path's length welded at located position p
        if closed:
            return (-p if rev else p) % total
        return total - p if rev else p

    u_end = u_of(pos0)
    if closed and u_end < run.length + 0.01:
        u_end += total  # its stations on the same lap
    step = path.length / (len(path.s) - 1)
    last = min(len(path.s) - 1, math.floor((u_end + reach_m) / step))
    d = np.angle(np.exp(1j * np.diff(qs[:, [-3, -1]], axis=0)))
    wind = np.vstack([np.zeros(2), np.cumsum(d, axis=0)])
    branch = [0]
    joins = {j: math.floor((u_end - sign * (pos0 - rows[j, 0])) / step + 1e-9) + 1 for j in branch}  # first after
    pose = poser(path, search, flange)
    joined: dict[int, list[State]] = {}
    for j in branch:
        v = (float(rows[j, 1]), float(rows[j, 2]), float(rows[j, 3]))
        lo, hi = wind[: j + 1].min(axis=0), wind[: j + 1].max(axis=0)
        joined.setdefault(joins[j], []).append(State(v, qs[j], wind[j], lo, hi, 0, -1 - j))
    first = min(joined)
    stations = walk(search, pose, range(first, last + 1), joined, bound)
    if not stations or first + len(stations) - 1 <= math.floor(u_end / step + 1e-9) + 1:
        return None
    return _joined(run, rows, qs, stations, first, (step, u_end, pos0, sign), total, closed, whole_m)


def walk(
    search: SeamSearch,
    pose: Callable[[int, tuple[float, float, float]], FloatArray],
    ks: range,
    joined: dict[int, list[State]],
    bound: float,
) -> list[list[State]]:
    """The beam at each fine station of ``ks`` in turn (until it is empty): the states that follow the beam at the
    station before, and those in ``joined`` at that station, by :func:`_steps`, then :func:`beam`."""
    stations: list[list[State]] = []
    for k in ks:
        cands: list[State] = []
        for st in joined.get(k, []):
            cands += _steps(search, pose, k, st, st.parent, bound)
        for i, st in enumerate(stations[-1] if stations else []):
            cands += _steps(search, pose, k, st, i, bound)
        kept = beam(cands)
        if not kept:
            break
        stations.append(kept)
    return stations


def poser(
    path: CurvePath, search: SeamSearch, flange: tuple[FloatArray, FloatArray] | None
) -> Callable[[int, tuple[float, float, float]], FloatArray]:
    """The torch pose (4, 4) at the fine station k with a setting (spin, work, travel offsets)."""
    one: dict[int, CurvePath] = {}

    def at(k: int, v: tuple[float, float, float]) -> FloatArray:
        if k not in one:
            sl = slice(k, k + 1)
            one[k] = replace(path, p_R=path.p_R[sl], t_R=path.t_R[sl], n_a_R=path.n_a_R[sl], n_b_R=path.n_b_R[sl],
                             s=path.s[sl])  # fmt: skip
        got = curve_poses(one[k], search.process, spin=v[0], work_offset=v[1], travel_offset=v[2], flange=flange)
        return np.asarray(got[0])

    return at


def _steps(
    search: SeamSearch,
    pose: Callable[[int, tuple[float, float, float]], FloatArray],
    k: int,
    st: State,
    parent: int,
    bound: float,
) -> list[State]:
    """The states at station k following ``st``: its setting held, turned or tilted one step (within the
    tolerances), each where IK warm-started from its joints holds it within the bounds."""
    pr = search.process
    s, w, t = st.v
    moves = [(s, w, t), (s + SPIN_STEP, w, t), (s - SPIN_STEP, w, t)]
    moves += [(s, w + dw, t) for dw in (TILT_STEP, -TILT_STEP) if abs(w + dw) <= pr.work_angle_tol + 1e-9]
    moves += [(s, w, t + dt) for dt in (TILT_STEP, -TILT_STEP) if abs(t + dt) <= pr.travel_angle_tol + 1e-9]
    if pr.spin_tol < math.pi - 1e-9:
        moves = [m for m in moves if abs(m[0]) <= pr.spin_tol + 1e-9]
    out = []
    for v in moves:
        q = _next(search, pose(k, v), st.q, bound)
        if q is None:
            continue
        step = np.angle(np.exp(1j * (q - st.q)))
        wind = st.wind + step[[-3, -1]]
        lo, hi = np.minimum(st.lo, wind), np.maximum(st.hi, wind)
        if _a46_fits(search, *(hi - lo)):
            out.append(State(v, q, wind, lo, hi, st.changes + (v != st.v), parent, st.root))
    return out


def beam(cands: list[State], width: int | None = None) -> list[State]:
    """At most ``width`` (:data:`BEAM`) states, the fewest setting changes first, at most :data:`PER_SETTING` IK
    branches of one setting, none within 0.01 rad of another of the same setting."""
    kept: list[State] = []
    per: dict[tuple[float, ...], list[FloatArray]] = {}
    for st in sorted(cands, key=lambda c: c.changes):
        key = tuple(round(x, 6) for x in st.v)
        same = per.setdefault(key, [])
        if len(same) >= PER_SETTING or any(float(np.abs(st.q - q).max()) < 0.01 for q in same):
            continue
        same.append(st.q)
        kept.append(st)
        if len(kept) >= (width or BEAM):
            break
    return kept


def _joined(
    run: Run, rows: FloatArray, qs: FloatArray, stations: list[list[State]], first: int,
    at: tuple[float, float, float, float], total: float, closed: bool, whole_m: float,
) -> Run:  # fmt: skip
    """``run`` (its stations ``rows`` and joints ``qs`` in weld order) up to the station the furthest state
    branched off, then that state's path; ``at``: the fine stations' spacing, the fine path's length welded at the
    run's end, that end along the located curve [m] and the weld's sense along it (+-1)."""
    step, u_end, pos0, sign = at
    chain: list[tuple[int, State]] = []
    i, k = 0, len(stations) - 1
    while True:
        st = stations[k][i]
        chain.append((first + k, st))
        if st.parent < 0:
            j = -1 - st.parent
            break
        i, k = st.parent, k - 1
    chain.reverse()
    new = np.array([[pos0 + sign * (kk * step - u_end), *st.v] for kk, st in chain])
    track = np.vstack([rows[: j + 1], new])
    q_track = np.vstack([qs[: j + 1], [st.q for _, st in chain]])
    a, b = (float(track[-1, 0]), run.b_m) if sign < 0 else (run.a_m, float(track[-1, 0]))
    lap = math.floor(a / total) * total if closed else 0.0
    track[:, 0] -= lap
    order = np.argsort(track[:, 0])
    whole = closed and b - a >= whole_m - 1e-6
    return replace(
        run, a_m=a - lap, b_m=b - lap, whole=whole, track=readonly(track[order]), q_track=readonly(q_track[order]),
        spare=False,
    )  # fmt: skip
