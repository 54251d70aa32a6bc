"""Which torch orientations the torch search tries for a seam, in which order (step 1 of
:mod:`cell.planning.seam_search`): both weld directions (one if not ``process.reversible``) x spins about the torch
axis (``spin_step`` apart, within the process's spin tolerance) x work/travel angle offsets (nominal first, then
widened in ``angle_step`` steps within their tolerances, docs/reference.md section 7). Values only: no IK here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cell.config.motion import PlanOptions
from cell.process.torch import WeldProcess


@dataclass(frozen=True)
class Candidate:
    """One way to hold the torch on a seam: weld direction, spin [rad] about the torch axis, work and travel
    angle offsets [rad] from the process's nominal angles."""

    reversed: bool
    spin: float
    work_offset: float
    travel_offset: float


def _offsets(tol: float, step: float) -> list[float]:
    """0, +-step, +-2 step, ... within +-tol, and +-tol itself."""
    k = math.floor(tol / step + 1e-9)
    out = [0.0] + [s * i * step for i in range(1, k + 1) for s in (1.0, -1.0)]
    if tol > k * step + 1e-9:
        out += [tol, -tol]
    return out


def candidate_groups(process: WeldProcess, options: PlanOptions) -> list[list[Candidate]]:
    """Candidate groups, one per (work, travel) angle setting, nominal first then widening. With one direction
    only (not ``process.reversible``) a travel offset also counts by its distance from the mirrored nominal (the
    other direction's tilt of the torch: push a in one direction is drag -a in the other), so the search widens
    about both as it would have with both directions free."""
    pr, opt = process, options

    def cost(wa: tuple[float, float]) -> tuple[float, float]:
        w, a = wa
        if pr.reversible:
            return abs(w) + abs(a), abs(w)
        return round(abs(w) + min(abs(a), abs(a + 2.0 * pr.travel_angle)), 9), abs(w)

    angles = sorted(
        (
            (w, a)
            for w in _offsets(pr.work_angle_tol, opt.angle_step)
            for a in _offsets(pr.travel_angle_tol, opt.angle_step)
        ),
        key=cost,
    )
    spins = sorted(  # ordered so that neighbours warm-start each other's IK; pi and -pi coincide
        {round(s, 12) for s in _offsets(pr.spin_tol, opt.spin_step) if -math.pi + 1e-9 < s <= math.pi + 1e-9}
    )
    directions = (False, True) if pr.reversible else (False,)
    return [[Candidate(rev, sp, w, a) for rev in directions for sp in spins] for w, a in angles]
