"""Locators by name: the one registry that knows which ``--method`` builds which locator from which spec; every list
of method names derives from it, and a method other than the scenario's runs with its spec's defaults."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import fields, replace
from typing import Any, NamedTuple

import numpy as np

from cell.config.seams import PART_TOLERANCE_M
from cell.errors import ScenarioError
from cell.geometry import invert, make_pose
from cell.scenario import (
    AnyLocatorSpec,
    OursLocatorSpec,
    PaperLocatorSpec,
    RansacLocatorSpec,
    Scenario,
)
from cell.seams.base import SeamLocator
from cell.types import Box


class Registered(NamedTuple):
    """One locator: its scenario spec class and the factory (spec, scenario) -> locator."""

    spec: type[AnyLocatorSpec]
    factory: Callable[[Any, Scenario], SeamLocator]


# Locators are imported lazily, in their factories: only what runs is loaded.
def _paper(spec: PaperLocatorSpec, scenario: Scenario) -> SeamLocator:
    from cell.seams.paper import PaperLocator

    return PaperLocator(spec.options)


def _ransac(spec: RansacLocatorSpec, scenario: Scenario) -> SeamLocator:
    from cell.seams.ransac import RansacLocator

    return RansacLocator(spec.options)


def _ours(spec: OursLocatorSpec, scenario: Scenario) -> SeamLocator:
    from cell.seams.ours import OursLocator, OursOptions

    # The exact crop, so an end where the cloud is cut off is refused, not reported.
    ws = scenario.perception.workspace
    lo, hi = np.array(ws.min_m), np.array(ws.max_m)
    workspace_R = Box(invert(scenario.X_WR) @ make_pose(p=(lo + hi) / 2.0), hi - lo)
    settings = {f.name: getattr(spec.options, f.name) for f in fields(spec.options)}
    return OursLocator(OursOptions(**settings, workspace_R=workspace_R))


LOCATORS: Mapping[str, Registered] = {
    "paper": Registered(PaperLocatorSpec, _paper),
    "ransac": Registered(RansacLocatorSpec, _ransac),
    "ours": Registered(OursLocatorSpec, _ours),
}
METHODS: tuple[str, ...] = tuple(LOCATORS)


def _entry(method: str) -> Registered:
    entry = LOCATORS.get(method)
    if entry is None:
        raise ScenarioError(f"unknown locator method {method!r}; valid: {', '.join(METHODS)}")
    return entry


def locator_spec(scenario: Scenario, method: str | None = None) -> AnyLocatorSpec:
    """The spec ``method`` runs with: the scenario's ``locator`` when it is that method's, else its defaults."""
    if method is None or method == scenario.locator.method:
        return scenario.locator
    return _entry(method).spec()


def with_method(scenario: Scenario, method: str | None) -> Scenario:
    """The scenario with ``method``'s spec as its ``locator`` (unchanged when it already is, or ``method`` is None):
    what a run with ``--method`` records as its configuration."""
    spec = locator_spec(scenario, method)
    return scenario if spec is scenario.locator else scenario.model_copy(update={"locator": spec})


def with_options(scenario: Scenario, method: str, overrides: Mapping[str, Any]) -> Scenario:
    """The scenario running ``method`` with ``overrides`` merged into that method's options (its spec's, or the
    defaults); ScenarioError naming the key when one is not an option of ``method``."""
    spec = locator_spec(scenario, method)
    valid = [f.name for f in fields(spec.options)]
    unknown = sorted(set(overrides) - set(valid))
    if unknown:
        raise ScenarioError(
            f"unknown key(s) locator.options.{', '.join(unknown)} of {method}; valid: {', '.join(valid)}"
        )
    try:
        options = replace(spec.options, **overrides)
    except (TypeError, ValueError) as e:
        raise ScenarioError(f"locator.options of {method}: {e}") from None
    return scenario.model_copy(update={"locator": spec.model_copy(update={"options": options})})


def part_tolerance_m(scenario: Scenario, method: str | None = None) -> float:
    """How far [m] an as-built end may lie from the aligned map's, for ``method``'s seams: our locator's
    ``map_tolerance_m`` when it runs, else the project's part tolerance (``PART_TOLERANCE_M``)."""
    options = locator_spec(scenario, method).options
    return float(getattr(options, "map_tolerance_m", PART_TOLERANCE_M))


def make_locator(method: str, scenario: Scenario) -> SeamLocator:
    """Build the locator ``method`` from its spec (:func:`locator_spec`) and the scenario (ours' workspace crop)."""
    entry = _entry(method)
    return entry.factory(locator_spec(scenario, method), scenario)
