"""``cell krl check`` on the linear track's external axis E1: a program that states its track (header comment) or a
check given the limits wants E1 in every point, within the limits; a program without a track keeps E1 at 0. The
tiny cell's program is written once and its E1 values edited by hand (the track's own export is another module's)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from test_krl import HOME, OBSTACLES, PROCESS, SEAMS, URDF
from typer.testing import CliRunner

from cell.cli import app
from cell.export.checks.calls import check_all, fixed_base
from cell.export.checks.kinematics import check_kinematics
from cell.export.checks.program import Program, check_program, read_programs, stated_track
from cell.export.post import write_program
from cell.export.program import ProgramJob
from cell.geometry import make_pose, rot_z
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds

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


def test_the_kinematic_check_moves_the_base_by_e1_along_the_stated_axis(tmp_path: Path) -> None:
    """Every Cartesian point moved 3 m along the track (far out of the arm's reach from the base at E1 = 0) with
    E1 = 3000 mm: the arm, carried there, reaches each as planned; without the carriage it reaches none."""
    robot = RobotModel.from_urdf(URDF)
    X_RB = make_pose(rot_z(np.pi / 2), [0.1, 0.0, 0.0])  # a turned base: the axis is turned into it
    job = ProgramJob(plan_welds(robot, SEAMS[:1], HOME, PROCESS, OBSTACLES), robot, "T", X_RB=X_RB)
    write_program("krl", job, tmp_path)
    shift_B = X_RB[:3, :3].T @ np.array([3000.0, 0.0, 0.0])  # [mm] along the track's axis (x of R)

    def moved(m: re.Match[str]) -> str:
        xyz = [float(v) + d for v, d in zip(m.group(2, 3, 4), shift_B, strict=True)]
        return f"{m.group(1)}{{X {xyz[0]:.3f}, Y {xyz[1]:.3f}, Z {xyz[2]:.3f}{m.group(5)}, E1 3000.0"

    dat = (tmp_path / "T.dat").read_text()
    pattern = r"^(DECL E6POS \w+=)\{X ([-\d.]+), Y ([-\d.]+), Z ([-\d.]+)(.*?), E1 [-\d.]+"
    dat, n = re.subn(pattern, moved, dat, flags=re.M)
    assert n >= 3
    (tmp_path / "T.dat").write_text(dat)
    src = (tmp_path / "T.src").read_text()
    (tmp_path / "T.src").write_text(src.replace("DEF T( )\n", f"DEF T( )\n{TRACK.replace('1500.0', '5000.0')}\n"))
    programs, _ = read_programs(tmp_path)
    assert check_all(programs, robot) == []
    fixed = fixed_base(programs[0]).dat.decls
    original = read_programs(written_dir(tmp_path, job))[0][0].dat.decls
    for name, d in original.items():
        if d.type == "E6POS":
            assert all(abs(fixed[name].value[k] - d.value[k]) < 2e-3 for k in "XYZ"), name
    assert {f.code for f in check_kinematics(programs[0], robot)} == {"kinematics"}  # the base left at E1 = 0


def written_dir(tmp_path: Path, job: ProgramJob) -> Path:
    d = tmp_path / "original"
    write_program("krl", job, d)
    return d
