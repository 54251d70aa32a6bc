"""``cell rescan``'s re-scan of a whole detection: the straight seams' (:func:`cell.pipeline.rescan.rescan_detection`),
then the curved seams' on the loop ``cell weld`` runs (:func:`cell.pipeline.curved.rescan.rescan_curves`), each
curve chosen by the same mode or asked for by id; every curved seam the choice leaves says why. Frames: R; metres."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from cell.pipeline.curved.choice import chosen_curves
from cell.pipeline.curved.rescan import rescan_curves
from cell.pipeline.detect import Progress, quiet
from cell.pipeline.geometry import MotionScene, motion_scene
from cell.pipeline.last_check import joined
from cell.pipeline.records import Detection
from cell.pipeline.rescan import RescanMode, rescan_detection
from cell.station import Station
from cell.types.rescan import CurveRescan, Rescan


def rescan_all(
    station: Station,
    det: Detection,
    mode: RescanMode,
    *,
    seam_ids: Sequence[str] | None = None,
    motion: MotionScene | None = None,
    progress: Progress = quiet,
) -> tuple[Rescan, Detection]:
    """The straight seams re-scanned as :func:`~cell.pipeline.rescan.rescan_detection` does (the mode's choice and
    its escalation), then the curves of :func:`chosen_curves` from where that left the arm, as ``cell weld`` does;
    one re-scan record of both, with a :class:`CurveRescan` for every curved seam of the map in its order (those
    left: no view, and why), and the detection after both.

    seam_ids : these seams, straight or curved, instead of the mode's choice (``cell rescan --seams``); KeyError
    for an id the detection does not have. Raises as :func:`~cell.pipeline.rescan.rescan_seams` does without an
    arm, an eye-in-hand camera or the detection's scene."""
    curve_by_id = {c.id: c for c in det.curve_estimates}
    straight = curve_ids = None
    if seam_ids is not None:
        known = {e.id for e in det.estimates}
        unknown = [i for i in seam_ids if i not in known and i not in curve_by_id]
        if unknown:
            valid = ", ".join(sorted(known | set(curve_by_id)))
            raise KeyError(f"no seam {', '.join(unknown)} in the detection; seams: {valid}")
        straight = [i for i in seam_ids if i in known]
        curve_ids = [i for i in seam_ids if i in curve_by_id]
    if motion is None and station.arm is not None:
        motion = motion_scene(station.arm, det)
    rs, after = rescan_detection(station, det, mode, seam_ids=straight, motion=motion, progress=progress)
    curves, left = chosen_curves(after, mode, curve_ids)
    more = None
    if curves and motion is not None:
        progress(f"re-scanning {len(curves)} curved seams up close with the eye-in-hand camera")
        more, after = rescan_curves(station, after, motion=motion, progress=progress, curves=curves)
    done = {r.id: r for r in (more.curves if more is not None else ())}
    records = tuple(
        done.get(c.id) or CurveRescan(c.id, c, c, chosen=False, reason=left.get(c.id, "not re-scanned"))
        for c in after.curve_estimates
    )
    both = joined(rs, more)
    assert both is not None  # rs is never None
    return replace(both, curves=records), after
