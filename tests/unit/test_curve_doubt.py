"""A located curve is welded only where the straight seams' rule allows: its worst sample's bound within the weld
tolerance, its confidence high enough, an open curve's ends within the end tolerance; else refused with its code."""

from __future__ import annotations

import math

import numpy as np

from cell.pipeline.curved.welds import curve_doubt
from cell.scenario import load
from cell.types import CurveEstimate, SeamStatus
from cell.types.run import WeldReason


def _arc(sigma_mm: np.ndarray, *, closed: bool, ends_mm: tuple[float, float] = (0.0, 0.0)) -> CurveEstimate:
    n = len(sigma_mm)
    t = np.linspace(0.0, 2.0 * math.pi if closed else math.pi, n, endpoint=not closed)
    p = np.stack([0.05 * np.cos(t), 0.05 * np.sin(t), np.zeros(n)], axis=1)
    up = np.tile([0.0, 0.0, 1.0], (n, 1))
    return CurveEstimate(
        "T>P", SeamStatus.FOUND, p_RS=p, n_abutting_R=p / 0.05, n_receiving_R=up, closed=closed,
        sigma_m=sigma_mm / 1000.0, end_sigma_m=(ends_mm[0] / 1000.0, ends_mm[1] / 1000.0), confidence=0.9,
    )  # fmt: skip


def test_a_curve_is_refused_for_its_worst_sample_not_its_typical_one() -> None:
    sc = load("fence1")
    tight = np.full(200, sc.rescan.max_sigma_m * 1000.0)  # every sample at the limit [mm]
    assert curve_doubt(_arc(tight * 0.9, closed=True), sc) is None
    one_bad = tight * 0.5
    one_bad[137] = tight[0] * 1.1  # one stretch of the curve over the tolerance
    d = curve_doubt(_arc(one_bad, closed=True), sc)
    assert d is not None and d.code is WeldReason.LOW_CONFIDENCE and "worst sample" in d.detail


def test_an_open_curves_ends_must_be_within_the_end_tolerance_a_closed_one_has_none() -> None:
    sc = load("fence1")
    ok = np.full(100, sc.rescan.max_sigma_m * 1000.0 * 0.5)
    far = sc.rescan.max_end_sigma_m * 1000.0 * 1.2
    d = curve_doubt(_arc(ok, closed=False, ends_mm=(0.1, far)), sc)
    assert d is not None and d.code is WeldReason.END_UNCERTAIN
    assert curve_doubt(_arc(ok, closed=False, ends_mm=(0.1, far / 1.5)), sc) is None
    assert curve_doubt(_arc(ok, closed=True, ends_mm=(far, far)), sc) is None
