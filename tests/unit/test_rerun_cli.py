"""``--rerun FILE.rrd`` on ``cell weld`` / ``cell preview``: refused before any work when it cannot be written or
rerun-sdk is missing; and the recording's small numerical helpers (quaternions, the timeline's subsampling)."""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cell import pipeline
from cell.cli import app
from cell.errors import UsageError
from cell.geometry import rpy_to_matrix
from cell.pipeline.scene_view import subsample
from cell.preview.rerun import require_rerun
from cell.preview.timeline import quaternions_xyzw

runner = CliRunner()


@pytest.fixture
def no_run(monkeypatch: pytest.MonkeyPatch) -> None:
    """The pipeline must not start: a usage error is found before any work."""

    def refuse(*_: object, **__: object) -> None:
        raise AssertionError("the pipeline ran")

    monkeypatch.setattr(pipeline, "weld", refuse)
    monkeypatch.setattr(importlib.import_module("cell.pipeline.turnover"), "weld", refuse)  # weld_part's side A


def _one_error_line(argv: list[str], *needles: str) -> None:
    result = runner.invoke(app, argv)
    assert result.exit_code == 2, result.stderr
    lines = [ln for ln in result.stderr.strip().splitlines() if ln.startswith("error:")]
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    for n in needles:
        assert n in lines[0], lines[0]


@pytest.mark.parametrize("command", ["weld", "preview"])
@pytest.mark.parametrize("where", ["{file}/x.rrd", "{dir}"])
def test_unwritable_rerun_path_exits_2_before_any_work(tmp_path: Path, no_run: None, command: str, where: str) -> None:
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    target = where.format(file=a_file, dir=tmp_path)
    out = ["--out", str(tmp_path / "pv")] if command == "preview" else []
    _one_error_line([command, "fence1", *out, "--rerun", target], "--rerun")


@pytest.mark.parametrize("command", ["weld", "preview"])
def test_rerun_without_rerun_sdk_is_a_usage_error_naming_the_extra(
    tmp_path: Path, no_run: None, monkeypatch: pytest.MonkeyPatch, command: str
) -> None:
    monkeypatch.setitem(sys.modules, "rerun", None)  # `import rerun` raises ImportError
    _one_error_line(
        [command, "fence1", "--rerun", str(tmp_path / "x.rrd")],
        "--rerun",
        "uv sync --extra rerun",
        "pip install 'weld-cell[rerun]'",  # the brackets reach the terminal: messages are printed escaped
    )
    assert not (tmp_path / "x.rrd").exists()
    with pytest.raises(UsageError, match=re.escape("pip install 'weld-cell[rerun]'")):
        require_rerun()


def test_quaternions_give_back_the_rotations() -> None:
    rng = np.random.default_rng(7)
    rpy = rng.uniform(-np.pi, np.pi, (200, 3))
    rpy[:4] = np.array([[0, 0, 0], [np.pi, 0, 0], [0, np.pi, 0], [0, 0, np.pi]])  # the branches of Shepperd's method
    R = np.array([rpy_to_matrix(r) for r in rpy])
    q = quaternions_xyzw(R)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0) and np.all(q[:, 3] >= 0.0)
    x, y, z, w = q.T
    back = np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=1),
        ],
        axis=1,
    )
    np.testing.assert_allclose(back, R, atol=1e-12)


def test_subsample_keeps_the_rate_every_arc_switch_and_the_ends() -> None:
    times = np.arange(0, 10001, dtype=np.float64) * 1e-3  # 10 s at 1 kHz
    arc = (times >= 2.3456) & (times < 7.0011)
    idx = subsample(times, arc, 20.0)
    assert idx[0] == 0 and idx[-1] == len(times) - 1
    on, off = int(np.argmax(arc)), int(np.flatnonzero(arc)[-1]) + 1
    assert {on - 1, on, off - 1, off} <= set(idx.tolist())
    assert 200 <= len(idx) <= 205 and np.max(np.diff(times[idx])) <= 0.05 + 1e-9
