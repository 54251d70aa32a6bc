"""Which locator runs and with what options: ``locator: {method: <name>, options: {...}}``, one typed spec per
method, told apart by ``method`` (a discriminated union: the options are validated as that method's when the file
is loaded). The registry that builds a locator from its spec is :data:`cell.seams.registry.LOCATORS`."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from cell.config.seams import OursSettings, PaperOptions, RansacOptions
from cell.scenario.base import Model


class PaperLocatorSpec(Model):
    """The paper's locator (section 3.6): masks around the map seam, boundary points, extremes and frequencies."""

    method: Literal["paper"] = "paper"
    options: PaperOptions = PaperOptions()


class RansacLocatorSpec(Model):
    """The paper's baseline: RANSAC planes around the map seam, the weld line their intersection."""

    method: Literal["ransac"] = "ransac"
    options: RansacOptions = RansacOptions()


class OursLocatorSpec(Model):
    """Our map-guided locator: the two weld faces fitted near the map's seam, intersected, the ends found; it beats
    both others (docs/results.md, ``cell bench``)."""

    method: Literal["ours"] = "ours"
    options: OursSettings = OursSettings()


# Every spec has a ``method`` literal; the registry (cell.seams.registry.LOCATORS) holds one entry per member.
LOCATOR_SPECS: tuple[type[PaperLocatorSpec | RansacLocatorSpec | OursLocatorSpec], ...] = (
    PaperLocatorSpec,
    RansacLocatorSpec,
    OursLocatorSpec,
)
LocatorSpec = Annotated[PaperLocatorSpec | RansacLocatorSpec | OursLocatorSpec, Field(discriminator="method")]
AnyLocatorSpec = PaperLocatorSpec | RansacLocatorSpec | OursLocatorSpec


def spec_method(spec_class: type[Model]) -> str:
    """The ``method`` a locator spec class is for (its literal's one value)."""
    return str(spec_class.model_fields["method"].default)
