"""``cell weld fence1 --program DIR`` writes a program ``cell krl check DIR`` passes: arc statements with weld data on
every welded seam, the INI fold, TOOL/BASE by index, S and T on every E6POS matching the arm; a corrupted copy
fails with the finding that names what was broken. ``--controller rapid`` writes an ABB module of the same plan."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cell import pipeline
from cell.cli import app
from cell.cli.krl import EXIT_CHECK_FAILED
from cell.export.checks.kinematics import check_kinematics
from cell.export.checks.program import check_program, read_programs

runner = CliRunner()


@pytest.fixture(scope="module")
def program(tmp_path_factory: pytest.TempPathFactory, fence1_run: pipeline.WeldRun) -> Path:
    """fence1's program as ``cell weld fence1 --program DIR`` writes it (the session's run stands in for the weld)."""
    krl = tmp_path_factory.mktemp("krl")
    mp = pytest.MonkeyPatch()
    mp.setattr(pipeline, "weld", lambda *_, **__: fence1_run)
    try:
        result = runner.invoke(app, ["weld", "fence1", "--sides", "first", "--program", str(krl)])
    finally:
        mp.undo()
    assert result.exit_code in (0, 3), result.stderr
    return krl


def _copy(program: Path, tmp_path: Path, name: str) -> tuple[Path, Path]:
    d = tmp_path / name
    shutil.copytree(program, d)
    return d / "WELD_FENCE1.src", d / "WELD_FENCE1.dat"


def _findings(directory: Path, fence1_run: pipeline.WeldRun) -> list[tuple[str, str]]:
    assert fence1_run.arm is not None
    programs, found = read_programs(directory)
    for p in programs:
        found += check_program(p) + check_kinematics(p, fence1_run.arm.model)
    return [(f.code, f.message) for f in found]


def test_every_welded_seam_has_its_arc_statements_and_the_check_passes(
    program: Path, fence1_run: pipeline.WeldRun
) -> None:
    src = (program / "WELD_FENCE1.src").read_text()
    dat = (program / "WELD_FENCE1.dat").read_text()
    assert "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )" in src and "INTERRUPT ON 3" in src
    assert "BAS(#TOOL, 1)" in src and "BAS(#BASE, 1)" in src and ";- BASE_DATA[1] = {X " in src
    assert fence1_run.plan is not None
    segs = fence1_run.plan.segments
    welded = [s.seam_id for k, s in enumerate(segs) if s.kind == "weld" and segs[k - 1].kind != "weld"]
    assert sorted(set(welded)) == sorted(fence1_run.plan.order)  # every welded seam: one arc per pass
    on = [m[::-1] for m in re.findall(r"^;- ARC_ON seam (\S+) .*\n;FOLD ARCON (\w+) ", src, flags=re.M)]
    off = [m[::-1] for m in re.findall(r"^;- ARC_OFF seam (\S+) .*\n;FOLD ARCOFF (\w+) ", src, flags=re.M)]
    assert [s for _, s in on] == welded == [s for _, s in off]  # one ARC_ON ... ARC_OFF per welded seam
    for wdat, _ in on + off:
        assert re.search(rf"^DECL stArcDat_T {wdat}=", dat, flags=re.M)
    e6pos = re.findall(r"^DECL E6POS (\w+)=\{[^}]*\}", dat, flags=re.M)
    assert len(e6pos) >= 3 * len(welded)  # approach, weld and depart: LINs (the transfers are PTPs, E6AXIS)
    assert all(re.search(r", S \d+, T \d+,", ln) for ln in dat.splitlines() if ln.startswith("DECL E6POS"))
    result = runner.invoke(app, ["krl", "check", str(program)])
    assert result.exit_code == 0, result.stdout + result.stderr
    assert "passed" in result.stderr


def _drop_fold(text: str, kind: str) -> str:
    """The text without the first ``kind`` inline form (its fold and the folds inside)."""
    lines = text.split("\n")
    i = next(k for k, ln in enumerate(lines) if ln.startswith(f";FOLD {kind} "))
    depth = 0
    for j in range(i, len(lines)):
        depth += lines[j].startswith(";FOLD") - lines[j].startswith(";ENDFOLD")
        if depth == 0:
            return "\n".join(lines[:i] + lines[j + 1 :])
    raise AssertionError("unbalanced folds")


def test_a_corrupted_copy_fails_with_the_finding_that_names_it(
    program: Path, tmp_path: Path, fence1_run: pipeline.WeldRun
) -> None:
    src, _ = _copy(program, tmp_path, "no_arc_off")
    src.write_text(_drop_fold(src.read_text(), "ARCOFF"))
    codes = _findings(src.parent, fence1_run)
    assert ("arc", next(m for c, m in codes if "burns" in m)) in codes  # the next PTP or ARC_ON finds it burning
    result = runner.invoke(app, ["krl", "check", str(src.parent)])
    assert result.exit_code == EXIT_CHECK_FAILED
    assert re.search(r"^WELD_FENCE1\.src:\d+: arc: ", result.stdout, flags=re.M)

    src, dat = _copy(program, tmp_path, "no_decl")
    name = re.search(r"^LIN (XP\d+)", src.read_text(), flags=re.M).group(1)  # type: ignore[union-attr]
    dat.write_text(re.sub(rf"^DECL E6POS {name}=.*\n", "", dat.read_text(), flags=re.M))
    assert ("undeclared", f"LIN {name}: {name} is not declared") in _findings(src.parent, fence1_run)

    src, dat = _copy(program, tmp_path, "wrong_st")
    text = dat.read_text()
    m = re.search(r"^DECL E6POS (\w+)=\{[^}]*, S (\d+), T (\d+),", text, flags=re.M)
    assert m is not None
    wrong = int(m.group(2)) ^ 2  # the other side of the elbow
    dat.write_text(text.replace(m.group(0), m.group(0).replace(f", S {m.group(2)},", f", S {wrong},"), 1))
    found = _findings(src.parent, fence1_run)
    assert [c for c, msg in found] == ["status_turn"] and found[0][1].startswith(f"{m.group(1)}: S {wrong} T ")

    src, _ = _copy(program, tmp_path, "truncated")
    text = src.read_text()
    src.write_text(text[: len(text) * 2 // 3])
    assert ("structure", "no END: the file is truncated or not closed") in _findings(src.parent, fence1_run)


def test_rapid_module_of_the_same_plan(tmp_path: Path, fence1_run: pipeline.WeldRun) -> None:
    mp = pytest.MonkeyPatch()
    mp.setattr(pipeline, "weld", lambda *_, **__: fence1_run)
    try:
        result = runner.invoke(
            app, ["weld", "fence1", "--sides", "first", "--program", str(tmp_path), "--controller", "rapid"]
        )
    finally:
        mp.undo()
    assert result.exit_code in (0, 3), result.stderr
    text = (tmp_path / "WELD_FENCE1.mod").read_text()
    assert fence1_run.plan is not None
    segs = fence1_run.plan.segments
    arcs = sum(1 for k, s in enumerate(segs) if s.kind == "weld" and segs[k - 1].kind != "weld")
    starts = re.findall(r"^\s*ArcLStart (\w+),", text, flags=re.M)
    assert len(starts) == arcs == len(re.findall(r"^\s*ArcLEnd ", text, flags=re.M)) >= len(fence1_run.plan.order)
    bad = runner.invoke(app, ["weld", "fence1", "--program", str(tmp_path / "x"), "--controller", "inform"])
    assert bad.exit_code == 2 and "valid: krl, rapid" in bad.stderr
