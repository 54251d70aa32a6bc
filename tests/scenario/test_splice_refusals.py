"""The splice applies no registration correction the data cannot prove (issue 11, item 2), on real captures.

Exact extrinsics: nothing applied on fence1 (the weld run's own detection) and on the long parts seen along their
length (``scenarios/long-*.yaml``: the layouts whose registration estimates a 0.5-3 mm shift along the rails);
a 1 mm / 0.1 deg miscalibration of the fixed cameras is still taken out. The sweep over 5 seeds of every public
scenario is ``benchmarks/bench_splice.py``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from cell import pipeline
from cell import scenario as sc
from cell.export import detection_report
from cell.perception import perceive
from cell.perception.splice import REFUSALS


def _perceived(name: str) -> dict[str, dict[str, object]]:
    s = sc.load(name)
    cap = pipeline.capture(s)
    return perceive(cap.images, s.X_WR, s.perception, s.perception.health).splice_corrections()


def test_fence1_exact_extrinsics_nothing_applied(fence1_detection: pipeline.Detection) -> None:
    assert fence1_detection.scene is not None
    regs = fence1_detection.scene.perceived.spliced.registrations
    assert len(regs) == 2
    for r in regs:
        assert not r.accepted and r.refused in REFUSALS and np.array_equal(r.X_corr, np.eye(4))
    splice = detection_report(fence1_detection)["splice"]  # the report says so, per camera
    assert set(splice) == {"cam_left", "cam_right"}
    assert all(c["applied"] is False and c["refused"] in REFUSALS for c in splice.values())


@pytest.mark.parametrize("name", ["long-fence1", "long-ladder"])
def test_long_part_seen_along_its_length_nothing_applied(name: str) -> None:
    corrections = _perceived(name)
    assert set(corrections) == {"cam_left", "cam_right"}
    for c in corrections.values():
        assert c["applied"] is False and c["applied_mm"] == 0.0 and c["refused"] in REFUSALS


def test_miscalibrated_fixed_cameras_still_corrected(detected: Callable[..., pipeline.Detection]) -> None:
    """The session's detection of the cell (``detected``: test_closeup.py re-scans it), whose perception is
    ``perceive`` of its capture."""
    scene = detected("faults/extrinsics-fixed-off").scene
    assert scene is not None
    corrections = scene.perceived.splice_corrections()
    for name, c in corrections.items():
        assert c["applied"] is True and c["refused"] == "", name
        assert 1.2 < float(str(c["applied_mm"])) < 2.0 and c["directions"] == "6/6", name  # measured 1.55, 1.56
