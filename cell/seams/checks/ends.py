"""A located seam's ends checked against the aligned map, whatever the locator (frame R, metres): an end never
inside another part's body (:func:`check_ends` cuts it at that face), the located length as drawn within the part
tolerance and two end sigmas (else the offending end from the map). The rules: docs/seams.md section 3."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from cell.geometry import FloatArray
from cell.seams.sigma import drawn_end_sigma, length_tolerance_m
from cell.types import EndSource, Joint, Part, Reason, SeamEstimate, SeamStatus, WeldMap

INSIDE_MARGIN_M = 3e-4  # an end deeper than this inside another body is in it (surface noise apart) [m]
_STEP_M = 2.5e-4  # the walk along the seam that finds where it enters another body [m] (a 2 mm wall is 8 steps)
_BISECT = 10  # halvings of a step where the seam enters a body (0.25 mm / 2^10)
_NAMES = ("start", "end")
BEAD_LIFT_M = 1.5e-3  # how far out of the fillet corner the bead's walk runs [m]: inside a 4 mm leg's bead


def check_ends(
    weldmap: WeldMap, joints: Mapping[str, Joint], estimates: Sequence[SeamEstimate], tolerance_m: float
) -> tuple[SeamEstimate, ...]:
    """Every estimate with its ends checked against the aligned map (module docstring); ``tolerance_m`` [m]: the
    part tolerance (how far an as-built end may lie from the drawn one)."""
    return tuple(check_seam_ends(weldmap, joints.get(e.id), e, tolerance_m) for e in estimates)


def check_seam_ends(weldmap: WeldMap, joint: Joint | None, est: SeamEstimate, tolerance_m: float) -> SeamEstimate:
    """:func:`check_ends` of one estimate (unchanged unless FOUND); ``joint`` None: only the length and the other
    bodies are checked (every part counts as another)."""
    if est.status is not SeamStatus.FOUND:
        return est
    seam = weldmap.seam(est.id)
    a = np.asarray(est.p_start, float)
    length = float(np.linalg.norm(est.p_end - a))
    if length <= 0.0:
        return est
    t = (est.p_end - a) / length
    m0, m1 = (seam.p_start, seam.p_end) if float(t @ seam.direction) >= 0.0 else (seam.p_end, seam.p_start)
    s_map = [float((m0 - a) @ t), float((m1 - a) @ t)]
    if abs(length - seam.length) > 0.5 * seam.length + tolerance_m:
        return SeamEstimate(
            est.id,
            SeamStatus.NOT_FOUND,
            f"seam length {length * 1000:.1f} mm located, the map draws {seam.length * 1000:.1f} mm: not this joint "
            f"({est.reason})",
            code=Reason.LENGTH_MISMATCH,
            time_s=est.time_s,
        )
    s = [0.0, length]
    sig = [float(x) for x in est.end_sigma_m]
    src = list(est.end_source)
    notes: list[str] = []
    drawn = drawn_end_sigma(tolerance_m, seam.length)
    allowed = length_tolerance_m(tolerance_m, seam.length)

    def cut(k: int) -> None:
        """End k cut where the seam or its bead enters another body, walking out from the middle."""
        hit = bead_entry(weldmap.parts, joint, a, t, 0.5 * (s[0] + s[1]), s[k])
        if hit is None:
            return
        u, part = hit
        moved = abs(s[k] - u)
        s[k] = u
        src[k] = EndSource.OTHER_PART
        sig[k] = sig[k] if moved <= 2.0 * sig[k] else max(sig[k], drawn)
        notes.append(f"{_NAMES[k]} ran {moved * 1000:.1f} mm into part {part}: cut at its face")

    def from_map(k: int, why: str) -> None:
        s[k], src[k], sig[k] = s_map[k], EndSource.DRAWN, drawn
        notes.append(f"{_NAMES[k]} from the map: {why}")

    for k in (0, 1):
        cut(k)
    for _ in range(2):
        located = s[1] - s[0]
        excess = abs(located - seam.length) - (allowed + 2.0 * float(np.hypot(sig[0], sig[1])))
        if excess <= 0.0:
            break
        sign = 1.0 if located > seam.length else -1.0  # longer: the ends that run out offend; shorter: those in
        out = (s_map[0] - s[0], s[1] - s_map[1])  # each end's outward deviation from the map's [m]
        free = [k for k in (0, 1) if src[k] is not EndSource.DRAWN]
        if not free:
            break
        k = max(free, key=lambda j: sign * out[j] - 2.0 * sig[j])
        from_map(
            k,
            f"located length {located * 1000:.1f} mm, drawn {seam.length * 1000:.1f} mm (allowed "
            f"{allowed * 1000:.1f} mm and two sigmas of the ends)",
        )
    for k in (0, 1):
        if src[k] is EndSource.DRAWN:
            cut(k)  # the map's end too never inside another body
    if not notes:
        return est
    return replace(
        est,
        p_start=a + s[0] * t,
        p_end=a + s[1] * t,
        end_sigma_m=(sig[0], sig[1]),
        end_source=(src[0], src[1]),
        reason="; ".join([x for x in (est.reason, *notes) if x]),
    )


def bead_entry(
    parts: Sequence[Part], joint: Joint | None, a: FloatArray, t: FloatArray, mid: float, end: float
) -> tuple[float, str] | None:
    """Where the seam a + u t (a, t (3,), frame of ``parts``) or the bead along it (the line lifted
    :data:`BEAD_LIFT_M` out of the joint's fillet corner, along its bisector), walked from u = ``mid`` to u = ``end``
    [m], first enters a part other than the joint's two (deeper than :data:`INSIDE_MARGIN_M`): (u [m] at that
    part's face, its name), or None. ``joint`` None: the line alone, every part counting as another."""
    own = (joint.abutting, joint.receiving) if joint is not None else ()
    others = [p for p in parts if p.name not in own]
    hits = [h for o in (a, *_lifted(parts, joint, a)) if (h := _entry(others, o, t, mid, end)) is not None]
    return min(hits, key=lambda h: abs(h[0] - mid)) if hits else None


def _lifted(parts: Sequence[Part], joint: Joint | None, a: FloatArray) -> list[FloatArray]:
    """Point a (3,) [m] lifted :data:`BEAD_LIFT_M` out of the joint's fillet corner (along the bisector of its two
    faces' outward normals), or none (no joint, a part not in ``parts``, or faces with no corner between them)."""
    by_name = {p.name: p for p in parts}
    if joint is None or joint.abutting not in by_name or joint.receiving not in by_name:
        return []
    n = (
        by_name[joint.abutting].face_plane(joint.face_abutting)[0]
        + by_name[joint.receiving].face_plane(joint.face_receiving)[0]
    )
    norm = float(np.linalg.norm(n))
    return [a + BEAD_LIFT_M * n / norm] if norm > 1e-9 else []


def _entry(parts: Sequence[Part], a: FloatArray, t: FloatArray, mid: float, end: float) -> tuple[float, str] | None:
    """Where the line a + u t (a, t (3,)), walked from u = ``mid`` to u = ``end`` [m], first enters one of ``parts``
    (deeper than :data:`INSIDE_MARGIN_M`): (u [m], that part's name), or None. A part the middle lies in is not
    counted (the walk could not tell where it enters)."""
    n = max(int(np.ceil(abs(end - mid) / _STEP_M)), 1)
    u = np.linspace(mid, end, n + 1)
    p = a + u[:, None] * t
    lo, hi = min(mid, end), max(mid, end)
    first: tuple[int, Part] | None = None
    for part in parts:
        # Only a part whose bounding sphere meets the walked segment.
        c = part.center
        w = float(np.clip((c - a) @ t, lo, hi))
        if np.linalg.norm(a + w * t - c) > part.radius:
            continue
        inside = part.contains(p, -INSIDE_MARGIN_M)
        if inside[0]:
            continue
        hit = np.flatnonzero(inside)
        if len(hit) and (first is None or hit[0] < first[0]):
            first = (int(hit[0]), part)
    if first is None:
        return None
    i, part = first
    out_u, in_u = float(u[i - 1]), float(u[i])
    for _ in range(_BISECT):
        half = 0.5 * (out_u + in_u)
        if part.contains((a + half * t)[None], -INSIDE_MARGIN_M)[0]:
            in_u = half
        else:
            out_u = half
    # The walk found where it is deeper than the margin: the face lies the margin before that.
    back = INSIDE_MARGIN_M if end > mid else -INSIDE_MARGIN_M
    return out_u - back, part.name


__all__ = ["BEAD_LIFT_M", "INSIDE_MARGIN_M", "bead_entry", "check_ends", "check_seam_ends"]
