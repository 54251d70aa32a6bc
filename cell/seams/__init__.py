"""Seams: pair each map seam with its joint, tell whether a camera can see it, locate it, and score it. The public
names load on first use (``from cell.seams import OursLocator`` imports only that locator's modules); the values
they read and return are in :mod:`cell.types`; modules with a leading underscore are this package's own."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cell.seams.base import BatchSeamLocator, SeamLocator
    from cell.seams.joint import fillet_bisector, find_joints, weld_faces
    from cell.seams.metrics import evaluate, seam_metrics, segment_errors, summarise
    from cell.seams.ours import OursLocator, OursOptions, SeamErrors
    from cell.seams.paper import PaperLocator
    from cell.seams.ransac import RansacLocator, RansacOptions
    from cell.seams.registry import METHODS, make_locator
    from cell.seams.sigma import ours_sigma, paper_sigma, ransac_sigma
    from cell.seams.truth import true_seams
    from cell.seams.visibility import UNDERSIDE_REASON

_HOME = {
    "BatchSeamLocator": "base",
    "SeamLocator": "base",
    "fillet_bisector": "joint",
    "find_joints": "joint",
    "weld_faces": "joint",
    "evaluate": "metrics",
    "seam_metrics": "metrics",
    "segment_errors": "metrics",
    "summarise": "metrics",
    "OursLocator": "ours",
    "OursOptions": "ours",
    "SeamErrors": "ours",
    "PaperLocator": "paper",
    "RansacLocator": "ransac",
    "RansacOptions": "ransac",
    "METHODS": "registry",
    "make_locator": "registry",
    "ours_sigma": "sigma",
    "paper_sigma": "sigma",
    "ransac_sigma": "sigma",
    "true_seams": "truth",
    "UNDERSIDE_REASON": "visibility",
}

__all__ = [
    "METHODS",
    "UNDERSIDE_REASON",
    "BatchSeamLocator",
    "OursLocator",
    "OursOptions",
    "PaperLocator",
    "RansacLocator",
    "RansacOptions",
    "SeamErrors",
    "SeamLocator",
    "evaluate",
    "fillet_bisector",
    "find_joints",
    "make_locator",
    "ours_sigma",
    "paper_sigma",
    "ransac_sigma",
    "seam_metrics",
    "segment_errors",
    "summarise",
    "true_seams",
    "weld_faces",
]


def __getattr__(name: str) -> Any:
    """A public name of the package, imported from its module on first use (PEP 562)."""
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{home}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
