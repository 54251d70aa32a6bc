"""The close-up re-scan's values: where the eye-in-hand camera looks from (:mod:`~cell.rescan.view_grid`,
:mod:`~cell.rescan.viewpoint`), which seams and the close-up scene, the fusion of two estimates
(:mod:`~cell.rescan.fusion`), and an escalated re-scan (:mod:`~cell.rescan.escalation`). The loop that moves the
arm and captures is the pipeline's (:mod:`cell.pipeline.rescan`): only the pipeline talks to a station."""

from cell.rescan.fusion import ends_within_tolerance, fuse, seams_to_rescan, within_tolerance

__all__ = ["ends_within_tolerance", "fuse", "seams_to_rescan", "within_tolerance"]
