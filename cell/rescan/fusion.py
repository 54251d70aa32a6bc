"""The close-up re-scan's values: which seams, the close-up's scene and the fusion of the close-up's estimate with
the first by inverse variance, across the seam and at each end (:func:`fuse`, :func:`fuse_along`). The loop that
moves the arm is :func:`cell.pipeline.rescan.rescan_seams`. Frame R, metres. The steps: docs/seams.md section 5."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from cell.config.rescan import CONFIDENCE_THRESHOLD, RescanOptions
from cell.errors import ScenarioError
from cell.geometry import FloatArray, invert
from cell.rescan.viewpoint import ViewTarget
from cell.types import Cloud, DepthImage, MapSeam, Part, SeamEstimate, SeamScene, SeamStatus
from cell.types.rescan import Rescan, SeamRescan

if TYPE_CHECKING:
    from cell.scenario import Scenario


CONSISTENT_SIGMAS = 3.0  # two ends further apart than this many combined sigmas disagree (:func:`fuse_along`)


# -- uncertainty and fusion --------------------------------------------------------------------------------


def fuse(
    first: SeamEstimate, closeup: SeamEstimate | None, sigma_first: float, sigma_closeup: float, scale_m: float
) -> tuple[SeamEstimate, float]:
    """Inverse-variance fusion of two estimates of one seam: (fused estimate, weight of the close-up).

    An estimate that is not FOUND, or has an infinite sigma, has no weight. The fused ends are matched (a
    reversed close-up is turned round) and weighted w = s1^2 / (s1^2 + s2^2); the fused confidence is
    1 / (1 + (sigma / scale_m)^2) of the fused sigma, on the first estimate's confidence scale, and the fused
    sigma is its ``sigma_m`` (a close-up alone keeps its own).
    """
    ok1 = first.status is SeamStatus.FOUND and math.isfinite(sigma_first)
    if closeup is None or closeup.status is not SeamStatus.FOUND or not math.isfinite(sigma_closeup):
        return first, 0.0
    if not ok1:
        conf = 1.0 / (1.0 + (sigma_closeup / scale_m) ** 2)
        return replace(closeup, confidence=conf, reason=f"close-up only; {closeup.reason}"), 1.0
    a, b = closeup.p_start, closeup.p_end
    ends_closeup, sources_closeup = closeup.end_sigma_m, closeup.end_source
    if np.linalg.norm(a - first.p_end) + np.linalg.norm(b - first.p_start) < np.linalg.norm(
        a - first.p_start
    ) + np.linalg.norm(b - first.p_end):
        a, b = b, a
        ends_closeup, sources_closeup = ends_closeup[::-1], sources_closeup[::-1]
    v1, v2 = sigma_first**2, sigma_closeup**2
    w = v1 / (v1 + v2) if v1 + v2 > 0.0 else 0.5
    sigma = math.sqrt(v1 * v2 / (v1 + v2)) if v1 + v2 > 0.0 else 0.0
    p_start, p_end = (1.0 - w) * first.p_start + w * a, (1.0 - w) * first.p_end + w * b
    # Along the fused line each end is fused on its own, by its end sigmas (the line across stays as fused above).
    u = (p_end - p_start) / max(float(np.linalg.norm(p_end - p_start)), 1e-12)
    ends, sigmas, sources = [], [], []
    for p, q1, q2, s1, s2, k1, k2 in zip(
        (p_start, p_end),
        (first.p_start, first.p_end),
        (a, b),
        first.end_sigma_m,
        ends_closeup,
        first.end_source,
        sources_closeup,
        strict=True,
    ):
        along, s_end = fuse_along(float((q1 - p) @ u), s1, float((q2 - p) @ u), s2)
        ends.append(p + along * u)
        sigmas.append(s_end)
        sources.append(k2 if s2 <= s1 else k1)
    fused = SeamEstimate(
        id=first.id,
        status=SeamStatus.FOUND,
        reason=f"fused, close-up weight {w:.2f}; close-up {closeup.reason}",
        p_start=ends[0],
        p_end=ends[1],
        confidence=1.0 / (1.0 + (sigma / scale_m) ** 2),
        time_s=first.time_s + closeup.time_s,
        sigma_m=sigma,
        end_sigma_m=(sigmas[0], sigmas[1]),
        end_source=(sources[0], sources[1]),
    )
    return fused, float(w)


def fuse_along(x1: float, s1: float, x2: float, s2: float) -> tuple[float, float]:
    """Fusion of a first position x1 and a close-up's x2 [m] along a seam, with standard deviations s1, s2 [m]:
    (fused position, its standard deviation). An infinite sigma has no weight (both infinite: x1, inf).

    Two positions within :data:`CONSISTENT_SIGMAS` of their combined sigma are fused by inverse variance. Two that
    disagree by more cannot both be right, and nothing says which is wrong: the close-up's position is kept (the
    nearer, finer view) with a sigma of at least half the disagreement, so that an end a confidently wrong
    estimate pulled away is re-scanned or refused (``end_uncertain``), never averaged into a small sigma.
    """
    if not math.isfinite(s2):
        return x1, s1
    if not math.isfinite(s1):
        return x2, s2
    v1, v2 = s1 * s1, s2 * s2
    gap = abs(x1 - x2)
    if gap > CONSISTENT_SIGMAS * math.sqrt(v1 + v2):
        return x2, max(s2, 0.5 * gap)
    if v1 + v2 <= 0.0:
        return 0.5 * (x1 + x2), 0.0
    return (x1 * v2 + x2 * v1) / (v1 + v2), math.sqrt(v1 * v2 / (v1 + v2))


# -- which seams ---------------------------------------------------------------------------------------------


def seams_to_rescan(
    estimates: Sequence[SeamEstimate],
    threshold: float = CONFIDENCE_THRESHOLD,
    max_sigma_m: float = math.inf,
    max_end_sigma_m: float = math.inf,
) -> list[str]:
    """Ids of the seams worth a close look: found with confidence below ``threshold``, a sigma over
    ``max_sigma_m`` [m] (too uncertain to weld, :func:`within_tolerance`) or an end's sigma over
    ``max_end_sigma_m`` [m] (:func:`ends_within_tolerance`), or visible but not found.

    ``threshold=math.inf`` selects every visible seam. Seams no camera can see (against the table) are left out.
    """
    out = []
    for e in estimates:
        if e.status is SeamStatus.NOT_FOUND or (
            e.status is SeamStatus.FOUND
            and (
                e.confidence < threshold
                or not within_tolerance(e, max_sigma_m)
                or not ends_within_tolerance(e, max_end_sigma_m)
            )
        ):
            out.append(e.id)
    return out


def ends_within_tolerance(estimate: SeamEstimate, max_end_sigma_m: float) -> bool:
    """Whether a found estimate's ends are certain enough to weld: each end's sigma along the seam at most
    ``max_end_sigma_m`` [m] (the end tolerance over the bound's factor, ``RescanSpec.max_end_sigma_m``)."""
    return estimate.status is SeamStatus.FOUND and max(estimate.end_sigma_m) <= max_end_sigma_m


def within_tolerance(estimate: SeamEstimate, max_sigma_m: float) -> bool:
    """Whether a found estimate is certain enough to weld: its sigma at most ``max_sigma_m`` [m] (the weld
    tolerance over the bound's factor, ``RescanSpec.max_sigma_m``)."""
    return estimate.status is SeamStatus.FOUND and estimate.sigma_m <= max_sigma_m


# -- the re-scan ----------------------------------------------------------------------------------------------


def eye_in_hand_camera(scenario: Scenario, name: str | None = None) -> str:
    """The name of the scenario's eye-in-hand camera (``name`` checked when given); ScenarioError if none."""
    eye = [n for n, c in scenario.cameras.items() if c.mount == "eye_in_hand"]
    if name is not None:
        if name not in eye:
            raise ScenarioError(f"camera {name!r} is not an eye-in-hand camera of {scenario.name!r}; those: {eye}")
        return name
    if not eye:
        raise ScenarioError(
            f"scenario {scenario.name!r} has no eye-in-hand camera (mount: eye_in_hand) to re-scan with"
        )
    return eye[0]


def closeup_scenario(scenario: Scenario, method: str, options: RescanOptions) -> Scenario:
    """The scenario with the locator options for close-up clouds merged in (only for the locator ``method``)."""
    from cell.seams.registry import with_options

    extra = options.closeup_locator_options.get(method)
    if not extra:
        return scenario
    return with_options(scenario, method, extra)


def crop_around(points_R: FloatArray, seam: MapSeam, margin: float) -> np.ndarray:
    """(n,) mask of the points (n, 3) inside the seam's axis-aligned bounding box grown by ``margin`` [m]."""
    lo = np.minimum(seam.p_start, seam.p_end) - margin
    hi = np.maximum(seam.p_start, seam.p_end) + margin
    return np.asarray(np.all((points_R >= lo) & (points_R <= hi), axis=1))


def closeup_scene(
    image: DepthImage, X_WR: FloatArray, seam: MapSeam, base: SeamScene, options: RescanOptions, voxel_m: float
) -> SeamScene:
    """A local SeamScene from one close-up image: its points in R (deprojected with the image's believed pose)
    inside the box around ``seam``; the aligned map, joints and table of ``base``."""
    from cell.perception import deproject, downsample

    # Deproject straight into R (one transform of the ~1e6 points instead of two): the image's X_WC becomes X_RC.
    in_R = replace(image, X_WC=invert(np.asarray(X_WR, dtype=float)) @ image.X_WC)
    p_R = deproject(in_R)
    p_R = p_R[crop_around(p_R, seam, options.crop_margin_m)]
    dense = Cloud(p_R, "R", np.zeros(len(p_R), np.int16), (image.camera,))
    return SeamScene(
        voxel=lambda: downsample(dense, voxel_m),
        dense=dense,
        weldmap=base.weldmap,
        joints=base.joints,
        table_z=base.table_z,
        eyes_R={image.camera: np.asarray(in_R.X_WC, dtype=float)[:3, 3]},
    )


def view_target(scene: SeamScene, seam: MapSeam, first: SeamEstimate) -> ViewTarget:
    """What a close-up view must see of ``seam``: its first estimate (the map's line when not found), its faces."""
    from cell.seams.joint import weld_faces

    joint = scene.joints[seam.id]
    n_a, _, n_b, _ = weld_faces(scene.weldmap, joint)
    a, b = (first.p_start, first.p_end) if first.status is SeamStatus.FOUND else (seam.p_start, seam.p_end)
    return ViewTarget(seam.id, a, b, n_a, n_b)


def occluders(scene: SeamScene, seam_id: str) -> tuple[Part, ...]:
    """The map's parts that may stand between the camera and the seam: all but the joint's own two."""
    joint = scene.joints[seam_id]
    return tuple(p for p in scene.weldmap.parts if p.name not in (joint.abutting, joint.receiving))


def estimate_sigma(est: SeamEstimate | None) -> float:
    """Standard deviation [m] of an estimate for fusion: its locator's sigma; infinite when there is none or it
    was not found."""
    if est is None or est.status is not SeamStatus.FOUND:
        return math.inf
    return est.sigma_m


__all__ = [
    "CONFIDENCE_THRESHOLD",
    "Rescan",
    "RescanOptions",
    "SeamRescan",
    "closeup_scenario",
    "closeup_scene",
    "crop_around",
    "ends_within_tolerance",
    "estimate_sigma",
    "eye_in_hand_camera",
    "fuse",
    "fuse_along",
    "occluders",
    "seams_to_rescan",
    "view_target",
    "within_tolerance",
]
