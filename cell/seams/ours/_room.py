"""How much of face B lies free beside face A before another part of the map covers it (frame R, metres): a brace
whose end meets a post 21 mm below a rail leaves face B a 21 mm strip, where a band as wide as a free face's
would leave no point to fit."""

from __future__ import annotations

import numpy as np

from cell.geometry import FloatArray
from cell.types import Part

_STEP_M = 0.001  # the probe's step across face B [m]
_OFF_M = 0.002  # the probe runs this far in front of face B, so that B itself never holds it [m]


def room_on_b(
    n_a: FloatArray,
    n_b: FloatArray,
    mids: FloatArray,
    others: tuple[Part, ...],
    reach: float,
    margin: float,
) -> float:
    """The width [m] of face B (normal n_b (3,)) free beside face A (normal n_a (3,)), from the seam's points
    ``mids`` (k, 3) away from A across B, up to the first of ``others`` (the map's parts but the joint's two,
    grown by ``margin``: the band the locator leaves about every other part); ``reach`` [m] when none lies that
    near (the width the locator looks at). The smallest over ``mids``."""
    e = n_a - float(n_a @ n_b) * n_b  # in face B, away from A
    norm = float(np.linalg.norm(e))
    if norm < 1e-9 or not others:
        return reach
    e /= norm
    steps = np.arange(0.0, reach + _STEP_M, _STEP_M)
    mids = np.asarray(mids, dtype=float).reshape(-1, 3)
    probe = (mids + _OFF_M * n_b)[:, None, :] + steps[None, :, None] * e  # (k, steps, 3): one probe per point
    flat = probe.reshape(-1, 3)
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    room = reach
    for part in others:
        if np.any(part.center + part.radius + margin < lo) or np.any(part.center - part.radius - margin > hi):
            continue  # its sphere cannot meet the probes
        inside = part.contains(flat, margin=margin).reshape(probe.shape[:2])
        hit = inside.any(axis=1)
        if np.any(hit):
            room = min(room, float(steps[np.argmax(inside[hit], axis=1)].min()))
    return room
