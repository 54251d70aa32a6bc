"""Options of our map-guided seam locator (:mod:`cell.seams.ours`): what a scenario sets
(:class:`~cell.config.seams.OursSettings`, ``locator.options`` when ``locator.method`` is ``ours``) and the run's
workspace crop, which the registry adds from the scenario's workspace."""

from __future__ import annotations

from dataclasses import dataclass

from cell.config.seams import OursSettings
from cell.types import Box


@dataclass(frozen=True)
class OursOptions(OursSettings):
    """Options of :class:`OursLocator`: the scenario's :class:`~cell.config.seams.OursSettings` and where the cloud
    was cropped."""

    workspace_R: Box | None = None  # where the cloud was cropped (frame R); None: the cloud's bounds along R's axes
