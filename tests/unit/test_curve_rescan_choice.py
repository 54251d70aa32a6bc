"""Which curved seams ``cell rescan`` re-scans (:func:`cell.pipeline.curved.rescan_all.chosen_curves`) and how its
report and table show every one, re-scanned or left with why; the re-scan itself through the pipeline:
tests/scenario/test_curve_rescan_cli.py."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from cell.cli.printout.rescan_table import print_rescan
from cell.export.reports.curve_report import add_curve_rescan
from cell.pipeline import Detection, evaluate
from cell.pipeline.curved.rescan_all import chosen_curves
from cell.types import Reason, SeamStatus, WeldMap
from cell.types.curve_estimate import CurveEstimate
from cell.types.rescan import CurveRescan, Rescan

LIMIT_M = 0.5e-3 / 3.0  # the weld tolerance's sigma


def _curve(cid: str, sigma_m: float, *, closed: bool = True) -> CurveEstimate:
    t = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    p = np.c_[0.03 * np.cos(t), 0.03 * np.sin(t), np.zeros_like(t)]
    n = np.tile([0.0, 0.0, 1.0], (len(t), 1))
    ends = (0.0, 0.0) if closed else (2 * sigma_m, 3 * sigma_m)
    return CurveEstimate(
        cid, SeamStatus.FOUND, p_RS=p, n_abutting_R=n, n_receiving_R=n, closed=closed,
        sigma_m=np.full(len(t), sigma_m), end_sigma_m=ends,
    )  # fmt: skip


CURVES = (
    _curve("over", 0.3e-3),  # over the tolerance: cell weld re-scans it
    _curve("within", 0.1e-3),
    CurveEstimate("unseen", SeamStatus.NOT_FOUND, "no camera sees the plate", Reason.NO_SUPPORT),
    CurveEstimate("lost", SeamStatus.NOT_FOUND, "too few points", Reason.LOW_CONFIDENCE),
    CurveEstimate("free", SeamStatus.NOT_SUPPORTED, "no two parts hold it"),
)


def _detection(curves: tuple[CurveEstimate, ...] = CURVES) -> Any:
    scenario: Any = SimpleNamespace(rescan=SimpleNamespace(max_sigma_m=LIMIT_M))
    _, summary = evaluate((), {})
    wm = WeldMap((), (), "mm", "inline")
    return Detection(scenario, "ours", wm, (), {}, {}, summary, curve_estimates=curves)


def test_mode_low_takes_the_curves_cell_weld_re_scans_and_says_why_it_leaves_the_others() -> None:
    chosen, left = chosen_curves(_detection(), "low")
    assert [c.id for c in chosen] == ["over", "unseen"]  # cell weld's doubtful_curves
    assert "within the 0.167 mm the weld tolerance allows (--all looks again)" in left["within"]
    assert "sigma up to 0.100 mm" in left["within"]
    assert left["lost"].startswith("not re-scanned: not located (too few points); --seams lost looks for it")
    assert left["free"] == "not re-scanned: never searched (no two parts hold it)"
    assert set(left) | {c.id for c in chosen} == {c.id for c in CURVES}  # none dropped


def test_all_takes_every_located_curve_and_ids_take_exactly_those_asked() -> None:
    chosen, left = chosen_curves(_detection(), "all")
    assert [c.id for c in chosen] == ["over", "within", "unseen"] and set(left) == {"lost", "free"}
    chosen, left = chosen_curves(_detection(), "low", ["lost", "within", "free"])
    assert [c.id for c in chosen] == ["within", "lost"]  # map order; a curve never searched is not looked for
    assert left["over"] == "not re-scanned: not among --seams" and "never searched" in left["free"]
    chosen, _ = chosen_curves(_detection(), "all", [])
    assert chosen == []  # --seams with straight ids only: no curve


def test_the_report_and_the_table_show_each_curve_before_and_after_or_why_it_was_left(
    capsys: pytest.CaptureFixture[str],
) -> None:
    before = _detection(CURVES[:2])
    fused = _curve("over", 0.04e-3, closed=False)  # made open to show its ends
    first = _curve("over", 0.3e-3, closed=False)
    rs = Rescan(
        (), (), (), (), np.zeros(6), True,
        curves=(
            CurveRescan("over", first, fused, (), 0.95, 1.5),
            CurveRescan("within", CURVES[1], CURVES[1], chosen=False, reason="not re-scanned: within it"),
        ),
    )  # fmt: skip
    rep: dict[str, Any] = {"seams": [], "rescan": {"seams": 0}}
    add_curve_rescan(rep, before, _detection((fused, CURVES[1])), rs)
    over, within = rep["seams"]
    assert over["curve"]["sigma_max_mm"] == 0.04 and over["rescan"]["sigma_max_mm_before"] == 0.3
    assert over["rescan"]["end_sigma_mm_before"] == [0.6, 0.9] and over["rescan"]["within_tolerance"]
    assert over["rescan"]["used"] and over["rescan"]["views"] == 0 and "not_welded" not in over
    assert not within["rescan"]["chosen"] and within["rescan"]["reason"] == "not re-scanned: within it"
    assert rep["rescan"]["curves"] == {"seams": 1, "used": 1, "within_tolerance": 1}
    rep |= {"scenario": "s", "method": "ours", "summary": {"lateral_mean_mm": None, "endpoint_mean_mm": None}}
    rep["summary_before_rescan"] = rep["summary"]
    rep["rescan"] |= {"used": 0, "motion_s": 1.5}
    print_rescan(rep)
    text = capsys.readouterr().out
    assert "curve over: sigma max 0.300 -> 0.040 mm, ends +-0.60/0.90 -> 0.08/0.12 mm (within the tolerance)" in text
    assert "curve within: not re-scanned: within it" in text
    assert "1 curves re-scanned, 1 now within the tolerance" in text
