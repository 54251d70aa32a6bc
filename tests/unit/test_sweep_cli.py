"""``cell sweep``'s usage errors, found before Ray starts: an unknown --vary word, an unknown stage, and an --out
folder that holds a different sweep (exit 2, one line, no traceback)."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from cell.cli import app

runner = CliRunner()


def _invoke(*args: str) -> tuple[int, str]:
    result = runner.invoke(app, ["sweep", *args])
    return result.exit_code, result.stderr


def test_unknown_vary_word_and_stage(tmp_path: Path) -> None:
    code, err = _invoke("fence1", "--n", "2", "--vary", "tolerances,colour", "--out", str(tmp_path / "a"))
    assert code == 2 and "--vary: unknown word(s) colour; valid: tolerances, placement" in err
    code, err = _invoke("fence1", "--n", "2", "--stage", "paint", "--out", str(tmp_path / "a"))
    assert code == 2 and "--stage 'paint'; valid: detect, plan, weld" in err
    assert "Traceback" not in err and not (tmp_path / "a").exists()  # refused before any work


def test_out_folder_of_another_sweep(tmp_path: Path) -> None:
    (tmp_path / "sweep.json").write_text(json.dumps({"format": 1, "scenario": "fence1", "stage": "detect"}))
    code, err = _invoke("fence1", "--n", "2", "--out", str(tmp_path))
    assert code == 2, err
    assert "holds a different sweep" in err and "--fresh" in err and "Traceback" not in err
    assert not (tmp_path / "runs.jsonl").exists()
