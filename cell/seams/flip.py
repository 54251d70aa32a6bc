"""Which turn of the part exposes the seams its first side leaves against the table: values only, from the aligned
map; the turns that rest stably on the table ranked by the seams they expose, the seams no turn exposes named with
the reason (docs/flip.md)."""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping
from dataclasses import replace

import numpy as np

from cell.geometry import FloatArray
from cell.resting import axis_rotation, set_down
from cell.seams.joint import fillet_bisector
from cell.seams.visibility import visibility
from cell.types import Joint, WeldMap
from cell.types.flip import FlipPlan

_FACING_DOWN_Z = -0.2  # a fillet whose bisector points further down than this cannot be reached from above
_TURNS = (math.pi, math.pi / 2.0, -math.pi / 2.0)  # half turn first, then onto a side
# The part must not tip over when nudged: tilted this far about the nearest edge of its support, its centre of
# mass still lies over the support (an upright fence on a 100 mm rail is not a resting part).
MIN_TIP_RAD = math.radians(15.0)


def principal_axes(weldmap_R: WeldMap) -> FloatArray:
    """(3, 3) the part's principal axes as columns, longest extent first: the axes of its largest box part's box
    (a welded frame's members are drawn square to each other; with no box part, the principal axes of all the
    vertices), ordered by the whole part's extent along them."""
    pts = np.concatenate([p.vertices() for p in weldmap_R.parts])
    boxes = [p for p in weldmap_R.parts if p.is_box]
    if boxes:
        axes = max(boxes, key=lambda p: p.volume).box.X_AB[:3, :3]
    else:
        axes = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)[2].T
    extent = np.ptp(pts @ axes, axis=0)
    return np.asarray(axes[:, np.argsort(-extent)])


def centre_of_mass(weldmap_R: WeldMap) -> FloatArray:
    """(3,) the part's centre of mass [m]: its parts' centres weighted by their volumes (one steel)."""
    vol = np.array([p.volume for p in weldmap_R.parts])
    centres = np.stack([p.center for p in weldmap_R.parts])
    return np.asarray((centres * vol[:, None]).sum(axis=0) / vol.sum())


def pivot(weldmap_R: WeldMap) -> FloatArray:
    """(3,) the part's centre the turn is made about: the middle of its extent along its principal axes."""
    axes = principal_axes(weldmap_R)
    pts = np.concatenate([p.vertices() for p in weldmap_R.parts]) @ axes
    return np.asarray(axes @ ((pts.min(axis=0) + pts.max(axis=0)) / 2.0))


def _why_left(turned: WeldMap, joint: Joint, table_z: float, table_xy: tuple[FloatArray, FloatArray] | None) -> str:
    """Why the seam of ``joint`` cannot be welded on the turned part ("" when it can be searched)."""
    visible, reason = visibility(turned, joint, table_z)
    if not visible:
        return f"still against the table after the turn ({reason})"
    bis = fillet_bisector(turned, joint)
    if float(bis[2]) < _FACING_DOWN_Z:
        return f"faces down after the turn (fillet bisector z {bis[2]:+.2f}): no torch reaches it from above"
    if table_xy is not None:
        seam = turned.seam(joint.seam_id)
        lo, hi = table_xy
        for p in (seam.p_start, seam.p_end):
            if np.any(p[:2] < lo[:2]) or np.any(p[:2] > hi[:2]):
                return "off the table after the turn"
    return ""


def plan_flip(
    weldmap_R: WeldMap,
    joints: Mapping[str, Joint],
    table_z: float,
    remaining: Collection[str],
    X_RM: FloatArray,
    *,
    allowed: bool = True,
    max_tilt_rad: float = math.radians(5.0),
    table_xy: tuple[FloatArray, FloatArray] | None = None,
) -> FlipPlan:
    """The turn that exposes the seams ``remaining`` (ids left against the table after side A).

    weldmap_R : the aligned map in R (+z up); joints : seam id -> joint; table_z : the table top in R [m].
    X_RM : (4, 4) the aligned map's pose now. table_xy : the table's (min, max) corners (3,) in R, if the part
    must stay on it. Returns the :class:`FlipPlan` (``go`` False, with its ``reason``, when no turn is made).
    """
    remaining = [s.id for s in weldmap_R.seams if s.id in set(remaining)]
    axes = principal_axes(weldmap_R)
    if not remaining:
        return FlipPlan("x", axes[:, 0], 0.0, 0.0, X_RM, X_RM, (), {}, reason="no seam is left for a second side")
    if not allowed:
        why = "flip.allowed is false: the part may not be turned (too heavy to turn); the seam stays underside"
        return FlipPlan(
            "x",
            axes[:, 0],
            0.0,
            0.0,
            X_RM,
            X_RM,
            (),
            dict.fromkeys(remaining, why),
            allowed=False,
            reason="the scenario forbids turning the part (flip.allowed: false)",
        )
    pts = np.concatenate([p.vertices() for p in weldmap_R.parts])
    com, c = centre_of_mass(weldmap_R), pivot(weldmap_R)
    best: tuple[tuple[int, int], FlipPlan] | None = None
    rank = 0
    for k, name in enumerate("xyz"[:2]):  # about the longest axis, then the middle one: a turn over, not a spin
        for angle in _TURNS:
            rank += 1
            X, tilt, margin = set_down(pts, com, axis_rotation(axes[:, k], angle), c, table_z)
            turned = weldmap_R.transformed(X, "R")
            left = {sid: _why_left(turned, joints[sid], table_z, table_xy) for sid in remaining}
            left = {sid: why for sid, why in left.items() if why}
            exposed = tuple(sid for sid in remaining if sid not in left)
            height = float((X[:3, :3] @ com + X[:3, 3])[2]) - table_z
            tip = math.atan2(margin, max(height, 1e-9))
            stable = margin > 0.0 and tilt <= max_tilt_rad and tip >= MIN_TIP_RAD
            reason = ""
            if not stable:
                reason = (
                    f"turned {math.degrees(angle):+.0f} deg about its {name} axis the part would lean "
                    f"{math.degrees(tilt):.1f} deg (at most {math.degrees(max_tilt_rad):.1f}) with its centre of "
                    f"mass {margin * 1000:+.0f} mm inside its support, {height * 1000:.0f} mm up (tips over at "
                    f"{math.degrees(tip):.0f} deg, needs {math.degrees(MIN_TIP_RAD):.0f})"
                )
            plan = FlipPlan(name, axes[:, k], angle, tilt, X @ X_RM, X_RM, exposed, left, stable=stable, reason=reason)
            score = (len(exposed) if stable else -1, -rank)
            if best is None or score > best[0]:
                best = (score, plan)
    assert best is not None
    plan = best[1]
    if not plan.stable:
        why = f"no turn of the part rests stably: {plan.reason}"
        return replace(plan, exposed=(), left=dict.fromkeys(remaining, why), reason=why)
    if not plan.exposed:
        why = "no single turn exposes any seam left: " + "; ".join(f"{s}: {w}" for s, w in plan.left.items())
        return replace(plan, reason=why)
    return plan
