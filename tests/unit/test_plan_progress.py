"""Planning progress: the planner counts seams searched / total, the pipeline passes the count to a progress
callable's ``count`` or prints a line every tenth, the CLI's bar draws it (a bar on a terminal, lines otherwise)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from rich.console import Console
from tiny_cell import HOME, OBSTACLES, URDF

from cell import scenario as sc
from cell.cli import bar as bar_module
from cell.cli.bar import Bar
from cell.motion.robot import RobotModel
from cell.pipeline.progress import seam_counter
from cell.planning.plan import plan_welds
from cell.process.torch import WeldProcess
from cell.types.plan import SeamTask

FAR = [
    SeamTask(
        f"far{k}",
        np.array([0.0, 2.2, 0.06]),
        np.array([0.06, 2.2, 0.06]),
        np.array([0, 0, 1.0]),
        np.array([0, -1.0, 0]),
    )
    for k in range(3)
]


def test_the_planner_counts_every_seam() -> None:
    seen: list[tuple[int, int]] = []
    plan = plan_welds(
        RobotModel.from_urdf(URDF),
        FAR,
        HOME,
        WeldProcess.from_spec(sc.ProcessSpec()),
        OBSTACLES,
        on_seam=lambda done, total: seen.append((done, total)),
    )
    assert seen == [(1, 3), (2, 3), (3, 3)]
    assert not any(o.feasible for o in plan.seams)


def test_the_pipeline_prints_a_line_every_tenth_without_a_bar() -> None:
    lines: list[str] = []
    count = seam_counter(lines.append)
    for k in range(1, 41):
        count(k, 40)
    assert lines == [f"planned {k}/40 seams" for k in (1, *range(4, 41, 4))]  # the first, then every tenth


def test_the_pipeline_hands_the_count_to_a_bar() -> None:
    got: list[tuple[str, int, int]] = []

    class WithBar:
        def __call__(self, msg: str) -> None:
            raise AssertionError("no lines when there is a bar")

        def count(self, what: str, done: int, total: int) -> None:
            got.append((what, done, total))

    count = seam_counter(WithBar())
    count(1, 2)
    count(2, 2)
    assert got == [("planning seams", 1, 2), ("planning seams", 2, 2)]


def test_the_bar_prints_lines_off_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    said: list[str] = []
    monkeypatch.setattr(bar_module, "say", said.append)
    monkeypatch.setattr(bar_module, "err", Console(file=io.StringIO(), force_terminal=False))
    b = Bar()
    for k in range(1, 21):
        b("planning seams", k, 20)
    assert said == [f"planning seams: {k}/20" for k in (1, *range(2, 21, 2))]


def test_the_bar_draws_on_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    said: list[str] = []
    out = io.StringIO()
    monkeypatch.setattr(bar_module, "say", said.append)
    monkeypatch.setattr(bar_module, "err", Console(file=out, force_terminal=True, width=80))
    b = Bar()
    for k in range(1, 6):
        b("planning seams", k, 5)
    assert said == []  # a bar, not lines
    assert "planning seams" in out.getvalue() and "5/5" in out.getvalue()
    assert b._progress is None  # done == total: the bar is closed
