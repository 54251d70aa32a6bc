"""The seams of a brought cloud's aligned map, located and screened (for :func:`cell.pipeline.cloud.locate_cloud`):
the steps of :func:`cell.pipeline.detect.locate` without its module's import of the station (a brought cloud never
pulls in the simulator), our locator built with the crop of the brought cloud rather than a scenario's workspace."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields, replace

import numpy as np

from cell.perception.align.drawn import past_drawn_edge
from cell.perception.seam_screen import screen
from cell.scenario import Scenario
from cell.types import Box, Reason, SeamEstimate, SeamScene, SeamStatus


def locate_seams(
    ss: SeamScene, scenario: Scenario, method: str, workspace_L: Box, missing: Mapping[str, str]
) -> tuple[SeamEstimate, ...]:
    """Every seam of ``ss``'s map (frame L) located by ``method`` (ours with the scenario's options, cut at
    ``workspace_L``), the underside ones NOT_VISIBLE, then screened (missing parts, occluders, doubt)."""
    from cell.seams.base import SeamLocator, locate_all
    from cell.seams.checks import check_ends
    from cell.seams.ours import OursLocator, OursOptions
    from cell.seams.registry import locator_spec, make_locator, part_tolerance_m

    if method == "ours":
        opts = locator_spec(scenario, "ours").options
        settings = {f.name: getattr(opts, f.name) for f in fields(opts)}
        locator: SeamLocator = OursLocator(OursOptions(**settings, workspace_R=workspace_L))
    else:
        locator = make_locator(method, scenario)
    rng = scenario.rng(f"locator/{method}")
    estimates = tuple(unseen_reason(e) for e in locate_all(locator, ss, rng))
    tolerance = part_tolerance_m(scenario, method)
    estimates = check_ends(ss.weldmap, ss.joints, estimates, tolerance)
    estimates = tuple(not_as_drawn(ss, e, tolerance) for e in estimates)
    return screen(ss, estimates, missing, scenario.perception.screen)


def not_as_drawn(ss: SeamScene, est: SeamEstimate, band_m: float) -> SeamEstimate:
    """A seam not found for want of its faces' points, whose faces the cloud continues past the drawing's edge of
    them (:func:`~cell.perception.align.drawn.past_drawn_edge`, within the part tolerance ``band_m`` [m]): the
    reason says so and how far (the part does not lie as drawn), rather than leave it to a hidden face."""
    if est.status is not SeamStatus.NOT_FOUND or est.code is not Reason.NO_SUPPORT:
        return est
    joint, seam = ss.joints[est.id], ss.weldmap.seam(est.id)
    points = np.asarray(ss.dense.points)
    past = [
        found
        for part, face in ((joint.receiving, joint.face_receiving), (joint.abutting, joint.face_abutting))
        if (found := past_drawn_edge(ss.weldmap, part, face, seam, points, band_m)) is not None
    ]
    if not past:
        return est
    return replace(est, reason=f"{est.reason}; yet {'; '.join(p.describe() for p in past)}")


def unseen_reason(est: SeamEstimate) -> SeamEstimate:
    """A weld face not seen is not placed from an edge here (NO_EDGES): say so instead of the edge's count."""
    cut = est.reason.find(" and its edge is not defined well enough")
    if est.status is not SeamStatus.NOT_FOUND or cut < 0:
        return est
    why = "; in a cloud without a camera's per-pixel density an unseen face is not placed from an edge"
    return replace(est, reason=est.reason[:cut] + ": shadowed or hidden from the sensor" + why)
