"""The page of fence1 (``cell weld fence1 --html``, ``cell preview fence1``): a DOM check of the figures it embeds.

The session's weld of fence1 (``fence1_run``) stands in for the pipeline's run, so no second weld is needed, and
``cell preview``'s page is the session's preview (``fence1_preview``, whose pictures and report are checked here
too, in one file so that one worker builds it): the page shows the robot (its URDF links, moved along the plan by
a slider), the table, the cameras' frusta, the results table with one row per seam, and the joint plots with every
weld's arc-on band labelled by its seam.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from page_dom import read
from shared_runs import Preview
from typer.testing import CliRunner

from cell import pipeline
from cell.cli import app


def check_page(path: Path, run: pipeline.WeldRun) -> None:
    """What the issue asks the page to show, read from the page's figure data and its results table."""
    assert path.stat().st_size < 10_000_000  # measured 6.9 MB with plotly.js inline
    figs, rows = read(path)
    names = [t.get("name") for t in figs["cell3d"]["data"]]
    assert "table" in names
    links = [n for n in names if str(n).startswith("robot ")]
    assert {"robot base_link", "robot link_1", "robot link_2", "robot link_3", "robot torch"} <= set(links)
    assert {f"camera {c}" for c in run.detection.scenario.cameras} <= set(names)
    assert {"cloud", "map parts", "seams found", "seams not visible"} <= set(names)
    records = run.records()
    assert [r["seam"] for r in rows] == [r.id for r in records]
    assert [r["status"] for r in rows] == [str(r.estimate.status) for r in records]
    done = "welded" if run.execution is not None else "planned"
    assert sum(r["cells"][4] == done for r in rows) == 12
    assert all(r["cells"][4] == "not visible" for r in rows if r["status"] == "not_visible")
    for row, rec in zip(rows, records, strict=True):
        if rec.metrics is not None:  # the error against the truth, as the report gives it
            assert float(row["cells"][3]) == pytest.approx(rec.metrics.paper_me_mm, abs=0.005)
    layout = figs["cell3d"]["layout"]
    steps = layout["sliders"][0]["steps"]
    assert steps[0]["label"] == "scan pose" and len(steps) > 40
    assert sum("weld" in s["label"] for s in steps) >= 12  # every weld's start and end among the poses
    # The camera looks at the part: the centre of the view is the aligned map's centre.
    scene = layout["scene"]
    lo = np.array([scene[f"{a}axis"]["range"][0] for a in "xyz"])
    hi = np.array([scene[f"{a}axis"]["range"][1] for a in "xyz"])
    aspect = np.array([scene["aspectratio"][a] for a in "xyz"])
    centre = np.array([scene["camera"]["center"][a] for a in "xyz"]) / aspect * (hi - lo) + (lo + hi) / 2.0
    part = np.vstack([p.vertices() for p in run.detection.weldmap_R.parts]) * 1000.0
    assert np.allclose(centre, (part.min(axis=0) + part.max(axis=0)) / 2.0, atol=1.0)
    # Joint plots: one row per joint, an arc-on band labelled by seam for every weld.
    joints = figs["joints"]
    assert [t["name"] for t in joints["data"]] == list(run.arm.model.limits.names) if run.arm else False
    labels = [a["text"] for a in joints["layout"]["annotations"] if a["text"] in {r.id for r in records}]
    assert sorted(labels) == sorted(w.id for w in run.seams if w.planned)
    assert all(math.isfinite(a["x"]) for a in joints["layout"]["annotations"] if a["text"] in labels)


def test_weld_html_page(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fence1_run: pipeline.WeldRun) -> None:
    monkeypatch.setattr(pipeline, "weld", lambda *a, **kw: fence1_run)
    page = tmp_path / "fence1.html"
    result = CliRunner().invoke(app, ["weld", "fence1", "--sides", "first", "--html", str(page)])
    assert result.exit_code == 0, result.stderr
    check_page(page, fence1_run)


def test_preview_draws_and_moves_nothing(fence1_preview: Preview) -> None:
    """``cell preview fence1``, run once per session (``fence1_preview``, whose page the next test checks)."""
    result, out = fence1_preview, fence1_preview.folder
    assert result.exit_code == 0, result.stderr
    for name in ("overview_top.png", "overview_3d.png", "overview_seams.png", "joints.png"):
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "plotly" in (out / "cell.html").read_text()[:200000]
    data = json.loads((out / "report.json").read_text())
    assert data["cycle_time_s"] == 0 and data["events"] == []
    assert all(not s["welded"] for s in data["seams"])
    assert sum(s["planned"] for s in data["seams"]) == 12


def test_preview_page(fence1_preview: Preview) -> None:
    """``cell preview`` writes the same page as ``cell.html`` beside its PNGs: the session's preview of fence1
    (``fence1_preview``, the real pipeline's plan, nothing moved), checked against the run it drew."""
    assert fence1_preview.exit_code == 0, fence1_preview.stderr
    assert fence1_preview.run.execution is None
    check_page(fence1_preview.folder / "cell.html", fence1_preview.run)
