"""What the session's scene fixtures (tests/conftest.py) hand the scenario tests."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

if TYPE_CHECKING:
    from cell import pipeline
    from cell.geometry import FloatArray
    from cell.scenario import Scenario

Noise = Literal["none", "realistic"]


@dataclass(frozen=True)
class Perceived:
    """A scenario captured and perceived once: the scene every locator reads and the true seams (frame R, m).

    capture : the images and the as-built parts (None for fence1 as shipped: its capture is the weld run's).
    """

    scenario: Scenario
    scene: pipeline.Scene
    truths: Mapping[str, tuple[FloatArray, FloatArray]]
    capture: pipeline.Capture | None


Scenes = Callable[[str, Noise], Perceived]  # the ``perceived`` fixture: (scenario name, noise) -> its Perceived
