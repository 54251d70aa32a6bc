"""``cell detect rhs`` headless, once (the session's ``detected``): fence1's drawing from rounded hollow sections,
with gaps, tacks and a bowed top rail (docs/bodies.md section 8). The parts-seen check passes with the default
threshold (only the samples of a top open to the sky count), and the seams end where the flats end into the radii.
Bounds are about twice what one run measures (2 December 2026: 12 of 12 found, endpoint 0.11 mm, lateral 0.10 mm,
every seam's ends within 0.25 mm and its line within 0.24 mm)."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from cell import pipeline
from cell.perception import part_coverage
from cell.types import SeamStatus

Detected = Callable[..., pipeline.Detection]


@pytest.fixture(scope="module")
def rhs(detected: Detected) -> pipeline.Detection:
    return detected("rhs")


def test_rhs_tubes_are_seen_whole_from_above(rhs: pipeline.Detection) -> None:
    assert rhs.scene is not None, rhs.summary
    assert rhs.scenario.perception.coverage.min_seen == pytest.approx(0.6)  # the default: no override
    ss = rhs.scene.seam_scene
    coverage = part_coverage(ss.weldmap, ss.dense, rhs.scenario.perception)
    assert min(coverage.values()) > 0.95  # 57-69 % when a tube's inner bottom wall counted as top


def test_rhs_seams_are_found_with_their_ends_at_the_flats_ends(rhs: pipeline.Detection) -> None:
    s = rhs.summary
    assert s.visible == 12 and s.found == 12, [e.reason for e in rhs.estimates if e.status is not SeamStatus.FOUND]
    assert s.endpoint_mean_mm < 0.25 and s.lateral_mean_mm < 0.2
    for e in rhs.estimates:
        m = rhs.metrics[e.id]
        assert m.endpoint_mm < 0.4 and m.lateral_mm < 0.4, e.id
