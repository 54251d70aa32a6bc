"""What a collision check answers, and the numpy-only parts of checking (:mod:`cell.motion.collision`, the only
coal importer, asks the distances): the :class:`Contact` found, the broad phase's lower bound of the distance
between bounding spheres and boxes (:func:`sphere_box_distance`), and conservative advancement along a path
(:func:`advance_along`). Frames: the robot base R [m].
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray


@dataclass(frozen=True)
class Contact:
    """A collision: link ``a`` against ``b`` (a link or an obstacle name), distance ``depth`` [m] (<= the
    threshold; negative = penetration), witness point p_R (3,) on ``a`` [m], at sample ``index`` of the path
    checked and, when the path was timed, time ``t`` [s]; q (dof,) the configuration."""

    a: str
    b: str
    depth: float
    p_R: FloatArray
    q: FloatArray
    index: int = 0
    t: float = float("nan")

    def describe(self) -> str:
        p = np.round(self.p_R * 1000.0, 1).tolist()
        when = f" at t = {self.t:.3f} s" if np.isfinite(self.t) else ""
        return f"{self.a} vs {self.b} at p_R = {p} mm (distance {self.depth * 1000:.1f} mm){when}"


def sphere_box_distance(
    R_RB: FloatArray, centre: FloatArray, half: FloatArray, c_R: FloatArray, radius: FloatArray
) -> FloatArray:
    """(m, k) [m]: distance from each sphere (centres c_R (m, 3), radii (m,)) to each box (rotations R_RB (k, 3, 3),
    centres (k, 3), half sizes (k, 3)), a lower bound on the distance of anything inside the sphere (negative or
    zero when they may touch)."""
    local = np.einsum("kji,mkj->mki", R_RB, c_R[:, None, :] - centre[None])
    out = np.linalg.norm(np.maximum(np.abs(local) - half[None], 0.0), axis=2)
    return np.asarray(out - radius[:, None])


def advance_along(
    step_bound: Callable[[FloatArray], tuple[float, Contact | None]],
    motion_bound: Callable[[FloatArray], float],
    q_path: npt.ArrayLike,
    times: npt.ArrayLike | None = None,
    min_step: float = 0.001,
) -> Contact | None:
    """First contact along a path of configurations (n, dof), linear in joint space between samples, by
    conservative advancement: ``step_bound(q)`` gives the motion [m] allowed from q before the next check (or the
    contact at q), ``motion_bound(dq)`` the most any arm point moves for a joint step dq. times : (n,) [s] to
    report when the contact happens (optional). ``min_step`` [m]: smallest motion between two checks (near contact
    the spacing shrinks to this, so a touch thinner than it can be missed). None when the whole path is clear."""
    Q = np.asarray(q_path, dtype=float)
    T = None if times is None else np.asarray(times, dtype=float)
    i, frac = 0, 0.0  # current position: Q[i] + frac (Q[i+1] - Q[i])
    n = len(Q)
    while True:
        q = Q[i] if frac == 0.0 or i + 1 >= n else Q[i] + frac * (Q[i + 1] - Q[i])
        step, hit = step_bound(q)
        if hit is not None:
            t = float("nan") if T is None else float(T[i] + frac * (T[min(i + 1, n - 1)] - T[i]))
            return Contact(hit.a, hit.b, hit.depth, hit.p_R, hit.q, i, t)
        budget = max(step, min_step)
        # advance along the path until the motion bound uses the budget
        while i + 1 < n:
            seg = motion_bound(Q[i + 1] - Q[i])
            left = (1.0 - frac) * seg
            if left <= budget:
                budget -= left
                i, frac = i + 1, 0.0
                continue
            frac += budget / seg
            break
        else:
            if frac == 0.0 and budget >= 0.0:
                # reached the last sample: check it once more exactly (it may be within the budget)
                _, hit = step_bound(Q[-1])
                if hit is not None:
                    t = float("nan") if T is None else float(T[-1])
                    return Contact(hit.a, hit.b, hit.depth, hit.p_R, hit.q, n - 1, t)
                return None


def deep_sample(
    check: Callable[[FloatArray], Contact | None], q_path: npt.ArrayLike, depth: float, probes: int = 32
) -> Contact | None:
    """A contact at least ``depth`` [m] deep (its distance at most -depth) at one of a path's samples (n, dof),
    probed coarse to fine (the middle sample, then the quarters, the eighths, ...), at most ``probes`` of them;
    None when none of those is that deep. ``check(q)`` is the contact at q or None."""
    Q = np.asarray(q_path, dtype=float)
    for k in itertools.islice(coarse_to_fine(len(Q)), probes):
        hit = check(Q[k])
        if hit is not None and hit.depth <= -depth:
            return hit
    return None


def coarse_to_fine(n: int) -> Iterator[int]:
    """The indices 0..n-1, each once, level by level: n // 2, then the quarters, the eighths, ...; the two ends
    last."""
    seen, level = {0, n - 1}, 1
    while len(seen) < n:
        for j in range(1, 2 * level, 2):
            k = (j * (n - 1)) // (2 * level)
            if k not in seen:
                seen.add(k)
                yield k
        level *= 2
    yield from (k for k in sorted({0, n - 1}) if n > 0)


def advance_linear(
    budgets: Callable[[FloatArray], tuple[FloatArray, Contact | None]],
    weights: FloatArray,
    q_path: npt.ArrayLike,
    times: npt.ArrayLike | None = None,
    min_step: float = 0.001,
) -> Contact | None:
    """:func:`advance_along` with a budget per class of pairs whose bound is linear in the joints' steps: class c
    nears by at most ``weights[c] @ |dq|`` [m] for a joint step dq (:mod:`cell.motion.collision.relative`);
    ``budgets(q)`` gives each class's allowed motion from q (m,) [m] or the contact at q. A step ends where the first
    class's budget (at least ``min_step``) is used; the classes' motions are summed along the path once."""
    Q = np.asarray(q_path, dtype=float)
    T = None if times is None else np.asarray(times, dtype=float)
    n = len(Q)
    seg = np.abs(np.diff(Q, axis=0)) @ np.asarray(weights, dtype=float).T  # (n - 1, classes)
    used = np.vstack([np.zeros(seg.shape[1]), np.cumsum(seg, axis=0)])  # each class's motion from the start
    x = 0.0  # where along the path: sample i and the fraction frac of the way to the next
    while True:
        i = min(int(x), n - 1)
        frac = x - i
        q = Q[i] if frac == 0.0 or i + 1 >= n else Q[i] + frac * (Q[i + 1] - Q[i])
        step, hit = budgets(q)
        if hit is not None:
            t = float("nan") if T is None else float(T[i] + frac * (T[min(i + 1, n - 1)] - T[i]))
            return Contact(hit.a, hit.b, hit.depth, hit.p_R, hit.q, i, t)
        if i + 1 >= n:
            return None
        here = used[i] + frac * seg[i]
        reach = here + np.maximum(step, min_step)
        x = n - 1.0
        for c in range(len(reach)):  # where each class's budget runs out: the first of them
            k = int(np.searchsorted(used[:, c], reach[c], side="right")) - 1
            if k < n - 1:
                x = min(x, k + (reach[c] - used[k, c]) / seg[k, c])
