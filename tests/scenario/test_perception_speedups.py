"""The speed-ups of perception give the answers of the plain computations they replace (docs/perception.md), on
fence1's own detection: the aligned map's two checks side by side, the alignment's coarse stages on sparser map
samples."""

from __future__ import annotations

import numpy as np
import pytest

from cell import pipeline
from cell.errors import AlignmentError
from cell.geometry import invert, make_pose
from cell.perception import align, align_map, check_alignment, check_alignment_unique, check_parts_seen
from cell.types import WeldMap


def _one_after_the_other(det: pipeline.Detection, weldmap_R: WeldMap) -> dict[str, str] | str:
    """What the two checks answer one after the other: the missing parts, or the code of the first refusal."""
    assert det.scene is not None
    scene, spec = det.scene, det.scenario.perception
    try:
        check_alignment_unique(weldmap_R, scene.perceived.registered, scene.alignment, spec.symmetry)
        return check_parts_seen(weldmap_R, scene.perceived.registered, spec, spec.coverage)
    except AlignmentError as e:
        return str(e.code)


def _side_by_side(det: pipeline.Detection, weldmap_R: WeldMap) -> dict[str, str] | str:
    assert det.scene is not None
    try:
        return check_alignment(weldmap_R, det.scene.perceived.registered, det.scene.alignment, det.scenario.perception)
    except AlignmentError as e:
        return str(e.code)


def test_checks_side_by_side_answer_as_one_after_the_other(fence1_detection: pipeline.Detection) -> None:
    det = fence1_detection
    aligned = det.weldmap_R
    assert _side_by_side(det, aligned) == _one_after_the_other(det, aligned) == {}
    # The map 4 cm off: half on the cloud, refused (off_cloud); 0.3 m off: the posts are missing. The same answer
    # whichever way the checks run.
    half_on = aligned.transformed(make_pose(p=(0.04, 0.0, 0.0)), "R")
    assert _side_by_side(det, half_on) == _one_after_the_other(det, half_on) == "off_cloud"
    off = aligned.transformed(make_pose(p=(0.3, 0.0, 0.0)), "R")
    missing = _one_after_the_other(det, off)
    assert isinstance(missing, dict) and set(missing) == {"POST_L", "POST_R"}
    assert _side_by_side(det, off) == missing


def test_coarse_stages_on_sparser_samples_reach_the_fine_fit(
    fence1_detection: pipeline.Detection, monkeypatch: pytest.MonkeyPatch
) -> None:
    det = fence1_detection
    assert det.scene is not None
    s = det.scenario
    nominal = pipeline.read_weldmap(s).transformed(invert(s.X_WR) @ s.X_WM, "R")
    cloud = det.scene.perceived.registered
    coarse = align_map(nominal, cloud, s.perception)
    np.testing.assert_allclose(coarse.X_RR_corr, det.scene.alignment.X_RR_corr, atol=1e-12)  # the pipeline's own
    monkeypatch.setattr(align, "_COARSE_SPACING", 1.0)  # every stage on the fine samples
    fine = align_map(nominal, cloud, s.perception)
    step = invert(fine.X_RR_corr) @ coarse.X_RR_corr
    assert np.linalg.norm(step[:3, 3]) < 10e-6  # [m] measured 0 (fence2: 4 um)
    assert np.arccos(np.clip((np.trace(step[:3, :3]) - 1.0) / 2.0, -1.0, 1.0)) < 10e-6  # [rad]
    assert coarse.fitness == pytest.approx(fine.fitness, abs=1e-3)
