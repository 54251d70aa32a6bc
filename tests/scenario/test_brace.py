"""The brace scenario (fence1 plus a mitred diagonal brace drawn as a MESH, a part that is not a box): the whole map
is detected per seam, never refused whole. fence1's seams are found as on fence1; each brace seam is either found
or refused with its own reason. One capture and perception for the session (``perceived`` in tests/conftest.py),
every locator on it."""

from __future__ import annotations

import pytest
from scenes import Scenes

from cell import pipeline
from cell.types import Reason, SeamStatus

BRACE = ("BRACE>POST_L:lower", "BRACE>POST_L:upper", "BRACE>POST_R:lower", "BRACE>POST_R:upper")
# fence1's seams each method finds on fence1 itself (realistic noise, measured: ours and the paper's 12 of the 12
# visible, RANSAC 8), less one
FENCE1_FOUND = {"ours": 11, "paper": 11, "ransac": 7}


@pytest.mark.parametrize("method", ["ours", "paper", "ransac"])
def test_brace_seams_go_per_seam(perceived: Scenes, method: str) -> None:
    p = perceived("brace", "realistic")
    assert not p.scene.seam_scene.weldmap.part("BRACE").is_box
    estimates = {e.id: e for e in pipeline.locate(p.scene, p.scenario, method)}
    assert len(estimates) == 20
    fence1 = [e for sid, e in estimates.items() if sid not in BRACE]
    assert sum(e.status is SeamStatus.NOT_VISIBLE for e in fence1) == 4  # the undersides, as on fence1
    assert sum(e.status is SeamStatus.FOUND for e in fence1) >= FENCE1_FOUND[method]
    for sid in BRACE:  # found, or refused with its own one-line reason
        e = estimates[sid]
        assert e.status is SeamStatus.FOUND or (e.code is not None and e.reason and "\n" not in e.reason), e
    if method == "paper":
        assert all(estimates[s].code is Reason.NOT_SUPPORTED for s in BRACE)
        assert estimates[BRACE[0]].reason.startswith("paper: part BRACE is a mesh")
    metrics, summary = pipeline.evaluate(tuple(estimates.values()), p.truths)
    assert summary.found >= FENCE1_FOUND[method]
    if method == "ours":  # the 19 mm fillets keep a window along them (measured: 3 of 4 found, 0.04-0.18 mm lateral)
        found = [sid for sid in BRACE if estimates[sid].status is SeamStatus.FOUND]
        assert len(found) >= 3
        assert max(metrics[sid].lateral_mm for sid in found) < 0.3
        assert max(metrics[sid].endpoint_mm for sid in found) < 0.8  # measured 0.15-0.59
