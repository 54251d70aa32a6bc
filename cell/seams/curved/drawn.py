"""A curved seam as the aligned map draws it, for a curve the fixed cameras did not locate (a surface no camera
sees: a rail's underside): its samples, both reference surfaces' outward normals there and the part tolerance as
its sigma, so that the close-up re-scan can plan views of it (docs/curves.md section 9). Frame R, metres."""

from __future__ import annotations

import numpy as np

from cell.config.seams import PART_TOLERANCE_M
from cell.seams.curved.locate import STEP_M, reference_surface
from cell.types import CurvedSeam, SeamStatus, WeldMap
from cell.types.curve_estimate import CurveEstimate


def drawn_estimate(wm: WeldMap, seam: CurvedSeam, sigma_m: float = PART_TOLERANCE_M) -> CurveEstimate | None:
    """``seam`` of the aligned map ``wm`` sampled :data:`STEP_M` apart as a FOUND estimate with sigma ``sigma_m``
    [m] at every sample (where the part may be as built) and the map's ends; None when it has no joint or a surface
    the locator has no model of (never searched)."""
    joint = seam.joint
    if joint is None:
        return None
    p = seam.sample(STEP_M)
    parts = (wm.part(joint.abutting), wm.part(joint.receiving))
    kinds = (joint.abutting_surface, joint.receiving_surface)
    normals = []
    for part, kind in zip(parts, kinds, strict=True):
        model = reference_surface(part, kind, p)
        if isinstance(model, str):
            return None
        g = model.implicit(np.zeros(model.size))(p)[1]
        normals.append(g / np.linalg.norm(g, axis=1, keepdims=True))
    closed = bool(getattr(seam.curve, "closed", False))
    return CurveEstimate(
        seam.id,
        SeamStatus.FOUND,
        "drawn: the aligned map's curve",
        p_RS=p,
        n_abutting_R=normals[0],
        n_receiving_R=normals[1],
        closed=closed,
        sigma_m=np.full(len(p), sigma_m),
        end_sigma_m=(0.0, 0.0) if closed else (sigma_m, sigma_m),
    )
