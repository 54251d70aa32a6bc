"""A weld job stopped by SIGTERM at its third seam's arc on, through the real command in a subprocess (the signal
is the process's): the seam is finished (never cut mid-bead), the report lists exactly the welds the journal holds,
exit 143; ``--resume`` (the same command, in this process) then welds exactly the rest, none twice, and the report
names each weld's run; a finished job is not resumed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cell.cli import app
from cell.journal import read_journal

CELL = str(Path(sys.executable).with_name("cell"))
runner = CliRunner()
# No close-ups: the journal is what is tested, and side A's nine seams that pass the gate without them are enough.
ARGS = ["weld", "fence1", "--sides", "first", "--noise", "none", "--rescan", "none", "--json", "r.json"]


def test_sigterm_mid_weld_then_resume_welds_exactly_the_rest(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    env = {**os.environ, "CELL_JOURNAL_SIGNAL": "arc_on@3=SIGTERM"}
    first = subprocess.run([CELL, *ARGS], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert first.returncode == 143, first.stderr
    last = first.stderr.strip().splitlines()[-1]
    assert last.startswith("exit 143: interrupted (SIGTERM)") and "3 seam(s) welded" in last, last
    st = read_journal(tmp_path / "r.journal.jsonl")
    assert len(st.welds) == 3 and not st.interrupted and st.end is not None and st.end["outcome"] == "interrupted"
    rep = json.loads((tmp_path / "r.json").read_text())
    assert {s["id"] for s in rep["seams"] if s["welded"]} == set(st.welds) and rep["error"]["exit_code"] == 143

    # The resume and the refusal need no signal: the same command in this process (no second interpreter to start).
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("CELL_JOURNAL_SIGNAL", raising=False)
    rest = runner.invoke(app, [*ARGS, "--resume", "."])
    assert rest.exit_code == 3, rest.stderr  # partial: the three seams the gate refuses without their close-ups
    st = read_journal(tmp_path / "r.journal.jsonl")
    offs = [r["seam"] for r in st.records if r["kind"] == "arc_off"]
    assert len(offs) == len(set(offs)) == 9 and st.runs == ("r1", "r2")  # every weldable seam of side A once
    rep = json.loads((tmp_path / "r.json").read_text())
    runs = {s["id"]: s["run"] for s in rep["seams"] if s["welded"]}
    assert rep["welded"] == 9 and sorted(runs.values()).count("r1") == 3 and set(runs.values()) == {"r1", "r2"}
    assert all(s["tcp_error_mm"]["rms"] <= 0.3 for s in rep["seams"] if s["welded"])  # measured <= 0.1 mm
    again = runner.invoke(app, [*ARGS[:2], "--resume", "."])
    assert again.exit_code == 2 and again.stderr.strip().splitlines()[-1].startswith("error: --resume")  # finished
