"""Our map-guided seam locator: fit the two weld faces near the map's seam, intersect them, find the ends.

The public names: :class:`OursLocator`, its :class:`OursOptions` and the standard errors behind a seam's confidence
(:class:`SeamErrors`); one concept per module (``locator``, ``options``, ``confidence``, ``_points``, ``_planes``,
``_geometry``, ``_faces``, ``_sides``, ``_ends``). The method, step by step: docs/seams.md section 1."""

from cell.seams.ours.confidence import NO_ERRORS, SUPPORT_FULL_MARKS, SeamErrors
from cell.seams.ours.locator import OursLocator
from cell.seams.ours.options import OursOptions

__all__ = ["NO_ERRORS", "SUPPORT_FULL_MARKS", "OursLocator", "OursOptions", "SeamErrors"]
