"""``cell krl check`` on the linear track's external axis E1: a program that states its track (header comment) or a
check given the limits wants E1 in every point, within the limits; a program without a track keeps E1 at 0. The
tiny cell's program is written once and its E1 values edited by hand (the track's own export is another module's)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from test_krl import HOME, OBSTACLES, PROCESS, SEAMS, URDF
from typer.testing import CliRunner

from cell.cli import app
from cell.export.krl_check import Program, check_program, read_programs, stated_track
from cell.export.post import write_program
from cell.export.program import ProgramJob
from cell.motion.plan import plan_welds
from cell.motion.robot import RobotModel

TRACK = (
    ";- Linear track E1 (KL-style, mathematically coupled): axis [1.0000, 0.0000, 0.0000] in $ROBROOT at E1 = 0;"
    " software limits -500.0 .. 1500.0 mm; speed 1000 mm/s, acceleration 2000 mm/s^2."
)


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> Path:
    robot = RobotModel.from_urdf(URDF)
    d = tmp_path_factory.mktemp("track")
    write_program("krl", ProgramJob(plan_welds(robot, SEAMS[:1], HOME, PROCESS, OBSTACLES), robot, "T"), d)
    return d


def _program(written: Path, tmp_path: Path, *, header: bool, e1: dict[str, str]) -> Program:
    """A copy of the program with the track header (or not) and the E1 of the named points set (``""``: removed)."""
    src, dat = (written / "T.src").read_text(), (written / "T.dat").read_text()
    if header:
        src = src.replace("DEF T( )\n", f"DEF T( )\n{TRACK}\n", 1)
    for name, value in e1.items():
        new = "" if value == "" else f", E1 {value}"
        dat, n = re.subn(rf"^(DECL E6(?:POS|AXIS) {name}=\{{.*?), E1 [-\d.]+", rf"\g<1>{new}", dat, flags=re.M)
        assert n == 1, name
    (tmp_path / "T.src").write_text(src)
    (tmp_path / "T.dat").write_text(dat)
    programs, found = read_programs(tmp_path)
    assert not found
    return programs[0]


def _track(p: Program, limits: tuple[float, float] | None = None) -> list[tuple[str, str]]:
    return [(f.code, f.message) for f in check_program(p, limits) if f.code == "track"]


def test_e1_is_checked_against_the_stated_or_given_limits(written: Path, tmp_path: Path) -> None:
    p = _program(written, tmp_path, header=True, e1={"XP1": "250.0", "XP2": "1499.5"})
    assert stated_track(p) == (True, (-500.0, 1500.0))
    assert _track(p) == []
    assert _track(p, (-100.0, 1000.0)) == [
        ("track", "XP2: E1 1499.5 mm is outside the track's limits -100 .. 1000 mm")  # the given limits win
    ]
    p = _program(written, tmp_path, header=True, e1={"XP1": "1500.4", "XP2": ""})
    assert _track(p) == [
        ("track", "XP1: E1 1500.4 mm is outside the track's limits -500 .. 1500 mm"),
        ("track", "XP2 has no E1: the program runs on a linear track"),
    ]


def test_without_a_track_every_e1_stays_zero(written: Path, tmp_path: Path) -> None:
    p = _program(written, tmp_path, header=False, e1={})
    assert stated_track(p) == (False, None) and _track(p) == []
    p = _program(written, tmp_path, header=False, e1={"XP1": "-20.0", "XHOME_PLAN": ""})
    assert _track(p) == [("track", "XP1: E1 -20 mm but the program states no linear track (and none was given)")]
    # given limits make it a track program: then a point without E1 is a finding too
    assert _track(p, (-50.0, 50.0)) == [("track", "XHOME_PLAN has no E1: the program runs on a linear track")]


def test_cli_takes_the_limits(written: Path, tmp_path: Path) -> None:
    _program(written, tmp_path, header=False, e1={"XP1": "80.0"})
    runner = CliRunner()
    r = runner.invoke(app, ["krl", "check", str(tmp_path / "T.src"), "--e1-limits", "-50", "50"])
    assert r.exit_code == 4 and re.search(r"^T\.dat:\d+: track: XP1: E1 80 mm is outside", r.stdout, flags=re.M)
    assert runner.invoke(app, ["krl", "check", str(tmp_path), "--e1-limits", "-50", "100"]).exit_code == 0
    assert runner.invoke(app, ["krl", "check", str(tmp_path), "--e1-limits", "5", "100"]).exit_code == 2
