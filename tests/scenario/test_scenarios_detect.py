"""Scenario tests: the real pipeline, headless, on real simulated data (render, splice, align, locate, measure).

Each scenario is captured and perceived once per noise setting for the whole session (``perceived`` in
tests/conftest.py; fence1 as shipped is the weld run's own detection); every locator then runs on that same scene,
as ``cell bench`` does. Bounds are the acceptance figures of the foundation issue (paper's method, noise-free: the
paper's own conditions, Table 1), and about twice what is measured where the issue gives none.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scenes import Noise, Scenes

from cell import pipeline
from cell.types import MetricsSummary, Reason, SeamEstimate, SeamMetrics, SeamStatus

# Paper's method, noise-free: mean paper ME bound [mm] (paper Table 1: 0.18 / 1.02 / 2.71).
PAPER_BOUND_MM = {"fence1-exact": 0.5, "fence1": 2.0, "fence2": 4.0}
# Paper's method, realistic noise: about twice the measured mean paper ME [mm] (0.85 / 1.13 / 0.82) and worst seam
# (1.17 / 4.05 / 2.09).
NOISY_MEAN_BOUND_MM = {"fence1-exact": 1.7, "fence1": 2.3, "fence2": 1.7}
NOISY_SEAM_BOUND_MM = {"fence1-exact": 2.4, "fence1": 8.0, "fence2": 4.2}


def run(
    perceived: Scenes, name: str, noise: Noise, method: str
) -> tuple[tuple[SeamEstimate, ...], dict[str, SeamMetrics], MetricsSummary]:
    p = perceived(name, noise)
    estimates = pipeline.locate(p.scene, p.scenario, method)
    per_seam, summary = pipeline.evaluate(estimates, p.truths)
    return estimates, per_seam, summary


@pytest.mark.parametrize("name", ["fence1-exact", "fence1", "fence2"])
def test_paper_method_noise_free_reproduces_table1(perceived: Scenes, name: str) -> None:
    estimates, _, summary = run(perceived, name, "none", "paper")
    assert len(estimates) == 16
    statuses = [e.status for e in estimates]
    # The four seams under the abutting parts lie against the table: reported, never invented.
    assert statuses.count(SeamStatus.NOT_VISIBLE) == 4
    assert all(e.code is Reason.UNDERSIDE for e in estimates if e.status is SeamStatus.NOT_VISIBLE)
    assert summary.found == 12
    assert summary.paper_me_mean_mm <= PAPER_BOUND_MM[name]


@pytest.mark.parametrize("name", ["fence1-exact", "fence1", "fence2"])
def test_realistic_noise_runs_and_reports_honest_figures(perceived: Scenes, name: str) -> None:
    estimates, per_seam, summary = run(perceived, name, "realistic", "paper")
    assert len(estimates) == 16
    for e in estimates:
        if e.status is SeamStatus.FOUND:
            m = per_seam[e.id]
            assert math.isfinite(m.paper_me_mm) and 0.0 <= m.paper_me_mm < NOISY_SEAM_BOUND_MM[name], e.id
        else:
            assert isinstance(e.code, Reason) and e.reason, f"{e.id} is {e.status.value} without a reason"
    # Noise makes the paper's method worse than in its noise-free conditions, but it stays in the right place.
    assert summary.found == 12
    assert summary.paper_me_mean_mm < NOISY_MEAN_BOUND_MM[name]


def test_alignment_recovers_the_placement_error(perceived: Scenes) -> None:
    p = perceived("fence2", "realistic")
    s, scene = p.scenario, p.scene
    X_RM_true = np.linalg.inv(s.X_WR) @ s.X_WM @ s.simulation.placement_error.X
    # fence2 lies 12 mm / 8 mm / 0.8 deg off its nominal place; the aligned map must be far closer than that.
    # (Parts carry their own deviations too: measured 2.5 mm of the 14.4 mm, the bound about twice that.)
    dp = np.linalg.norm(scene.X_RM[:3, 3] - X_RM_true[:3, 3])
    nominal = np.linalg.norm((np.linalg.inv(s.X_WR) @ s.X_WM)[:3, 3] - X_RM_true[:3, 3])
    assert dp < 0.35 * nominal


def test_same_seed_same_numbers(perceived: Scenes) -> None:
    first = perceived("fence1-exact", "realistic").capture  # the session's capture of it
    assert first is not None
    s = first.scenario
    a = first.images["cam_left"].depth
    b = pipeline.capture(s).images["cam_left"].depth
    np.testing.assert_array_equal(a, b)
    c = pipeline.capture(s.model_copy(update={"seed": s.seed + 1})).images["cam_left"].depth
    assert not np.array_equal(a, c)
