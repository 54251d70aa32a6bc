"""Locators by name: the one place that knows which ``--method`` builds which locator."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any, TypeVar

import numpy as np

from cell.errors import ScenarioError
from cell.geometry import invert, make_pose
from cell.scenario import Scenario
from cell.seams.base import SeamLocator
from cell.types import Box

T = TypeVar("T")

METHODS: tuple[str, ...] = ("paper", "ransac", "ours")


def make_locator(method: str, scenario: Scenario) -> SeamLocator:
    """Build the locator ``method`` with the scenario's options (imported lazily: only what runs is loaded)."""
    options: dict[str, Any] = dict(scenario.locator.options.get(method, {}))
    if method == "paper":
        from cell.seams.paper import PaperLocator

        return PaperLocator(scenario.locator.paper)
    if method == "ransac":
        from cell.seams.ransac import RansacLocator, RansacOptions

        return RansacLocator(_options(RansacOptions, options, method))
    if method == "ours":
        from cell.seams.ours import OursLocator, OursOptions

        opts = _options(OursOptions, options, method)
        # The exact crop, so an end where the cloud is cut off is refused, not reported.
        ws = scenario.perception.workspace
        lo, hi = np.array(ws.min_m), np.array(ws.max_m)
        workspace_R = Box(invert(scenario.X_WR) @ make_pose(p=(lo + hi) / 2.0), hi - lo)
        return OursLocator(dataclasses.replace(opts, workspace_R=workspace_R))
    raise ScenarioError(f"unknown locator method {method!r}; valid: {', '.join(METHODS)}")


def _options(cls: type[T], given: Mapping[str, object], method: str) -> T:
    """Fill an options dataclass from ``locator.options.<method>``, rejecting unknown keys with the valid ones."""
    valid = list(getattr(cls, "__dataclass_fields__", {}))
    unknown = sorted(set(given) - set(valid))
    if unknown:
        raise ScenarioError(f"unknown key(s) locator.options.{method}.{', '.join(unknown)}; valid: {', '.join(valid)}")
    try:
        return cls(**given)
    except (TypeError, ValueError) as e:
        raise ScenarioError(f"locator.options.{method}: {e}") from None
