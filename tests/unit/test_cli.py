"""The command line: results on stdout, one-line errors with documented exit codes, the JSON report contract."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from dxf_factory import design, make_maps
from typer.testing import CliRunner

from cell.cli import app
from cell.scenario import SCENARIO_DIR

runner = CliRunner()
REPO = Path(__file__).resolve().parents[2]


def invoke(*args: str) -> tuple[int, str, str]:
    result = runner.invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def assert_one_line_error(code: int, stderr: str, expected_code: int, *needles: str) -> None:
    assert code == expected_code, stderr
    lines = [ln for ln in stderr.strip().splitlines() if ln.startswith("error:")]
    assert len(lines) == 1, stderr
    assert "Traceback" not in stderr
    for n in needles:
        assert n in lines[0], lines[0]


def test_help_and_scenarios() -> None:
    code, out, _ = invoke("--help")
    assert code == 0 and "detect" in out
    code, out, _ = invoke("scenarios")
    assert code == 0
    for name in ("fence1-exact", "fence1", "fence2"):
        assert name in out


def test_map_info_lists_units_parts_and_seams() -> None:
    code, out, _ = invoke("map", "info", str(REPO / "maps" / "fence1.dxf"))
    assert code == 0
    assert "mm" in out
    for part in ("TOP_RAIL", "POST_L", "POST_R", "BOTTOM_RAIL"):
        assert part in out
    assert out.count("POST_L>TOP_RAIL:") == 4


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (b"\x00\x01\x02 not a drawing \xff" * 50, "DXF"),
        (b"hello, I am a text file\n", "DXF"),
    ],
)
def test_bad_dxf_gives_exit_11(tmp_path: Path, content: bytes, needle: str) -> None:
    bad = tmp_path / "bad.dxf"
    bad.write_bytes(content)
    code, _, err = invoke("map", "info", str(bad))
    assert_one_line_error(code, err, 11, needle)


def test_truncated_dxf_gives_exit_11(tmp_path: Path) -> None:
    good = (REPO / "maps" / "fence1.dxf").read_bytes()
    bad = tmp_path / "truncated.dxf"
    bad.write_bytes(good[: len(good) // 2])
    code, _, err = invoke("map", "info", str(bad))
    assert_one_line_error(code, err, 11, "truncated.dxf")


def test_unitless_dxf_gives_exit_12_and_names_the_fix(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    path = make_maps.write_map(tmp_path / "nounits.dxf", parts, seams, units=None)
    code, _, err = invoke("map", "info", str(path))
    assert_one_line_error(code, err, 12, "map.units")
    code, out, _ = invoke("map", "info", str(path), "--units", "mm")
    assert code == 0 and "POST_L" in out


def test_scenario_with_a_typo_gives_exit_10(tmp_path: Path) -> None:
    text = (SCENARIO_DIR / "fence1.yaml").read_text().replace("seed:", "sede:")
    path = tmp_path / "typo.yaml"
    path.write_text(text.replace("../maps/", str(REPO / "maps") + "/"))
    code, _, err = invoke("detect", str(path))
    assert_one_line_error(code, err, 10, "sede", "seed")


def test_unknown_scenario_and_method(tmp_path: Path) -> None:
    code, _, err = invoke("detect", "fence99")
    assert_one_line_error(code, err, 10, "fence1")
    code, _, err = invoke("detect", "fence1", "--method", "magic")
    assert code == 2 and "paper" in err


def test_unknown_scenario_name_gets_did_you_mean() -> None:
    code, _, err = invoke("detect", "fence11")
    assert_one_line_error(code, err, 10, "did you mean 'fence1'?")


def test_version_and_short_help() -> None:
    from cell.provenance import version

    code, out, _ = invoke("--version")
    assert code == 0 and out.startswith(f"cell {version()}")
    code, out, _ = invoke("weld", "-h")
    assert code == 0 and "--json" in out
    code, out, _ = invoke("-h")
    assert code == 0 and "--install-completion" in out and "--log-file" in out


def test_krl_is_the_deprecated_name_of_program(tmp_path: Path) -> None:
    """``--krl DIR`` still writes the program (whatever the controller) and says to use ``--program``; not both."""
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    code, _, err = invoke("weld", "fence1", "--krl", str(a_file), "--controller", "rapid")
    assert_one_line_error(code, err, 2, "--program")
    assert "warning: --krl is deprecated: use --program DIR" in " ".join(err.split())
    code, _, err = invoke("weld", "fence1", "--krl", str(tmp_path), "--program", str(tmp_path))
    assert_one_line_error(code, err, 2, "--krl is the deprecated name of --program")
    code, out, _ = invoke("weld", "-h")
    assert "--program" in out and "--krl" not in out


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (("detect", "fence1", "--json", "{file}/r.json"), "--json"),
        (("detect", "fence1", "--save-cloud", "{dir}"), "--save-cloud"),
        (("detect", "fence1", "--save-cloud", "-"), "--save-cloud"),
        (("weld", "fence1", "--json", "{dir}"), "--json"),
        (("weld", "fence1", "--program", "{file}"), "--program"),
        (("weld", "fence1", "--program", "{file}/krl"), "--program"),
        (("preview", "fence1", "--out", "{file}"), "--out"),
        (("rescan", "fence1", "--json", "{file}/sub/r.json"), "--json"),
        (("bench", "fence1", "--out", "{file}"), "--out"),
    ],
)
def test_unwritable_output_exits_2_before_any_work(
    tmp_path: Path, args: tuple[str, ...], option: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A path under a file, a folder where a file goes, a file where a folder goes: one line, exit 2, before the
    simulator is started (nothing captured)."""
    from cell.sim.cell import SimCell

    started: list[bool] = []
    monkeypatch.setattr(SimCell, "__init__", lambda *a, **k: started.append(True))
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    argv = [a.format(file=a_file, dir=tmp_path) for a in args]
    code, _, err = invoke(*argv)
    assert not started  # nothing was captured
    assert_one_line_error(code, err, 2, option)
    assert ".part" not in err and "tmp" not in err.replace(str(tmp_path), "")


def test_usage_errors_exit_2_before_any_work(monkeypatch: pytest.MonkeyPatch) -> None:
    code, _, err = invoke("map", "info", str(REPO / "maps" / "fence1.dxf"), "--units", "ft")
    assert_one_line_error(code, err, 2, "--units", "mm")
    monkeypatch.delenv("DISPLAY", raising=False)
    code, _, err = invoke("weld", "fence1", "--gui")
    assert_one_line_error(code, err, 2, "--gui", "DISPLAY")
    code, _, err = invoke("rescan", "fence1", "--seams", "BOGUS")
    assert_one_line_error(code, err, 2, "--seams", "BOGUS", "POST_L>TOP_RAIL:+x")
    code, _, err = invoke("rescan", "track-post", "--seams", "POST>PLATE:circle,BOGUS")  # a curve's id is one
    assert_one_line_error(code, err, 2, "--seams: no seam BOGUS in the map; seams: POST>PLATE:circle")
    code, _, err = invoke("detect", "fence1", "--format", "xml")
    assert_one_line_error(code, err, 2, "--format", "csv")
    code, _, err = invoke("--log-file", str(REPO / "README.md" / "x.log"), "scenarios")
    assert_one_line_error(code, err, 2, "--log-file", "is not a folder")


def test_the_console_script_ends_a_usage_error_with_one_error_line() -> None:
    """Through ``cell.cli.main`` (typer's own parsing errors): the last line of stderr says why, no box."""
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-c", "from cell.cli import main; main()", "weld", "fence1", "--bogus"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 2
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("error:") and "--bogus" in last, done.stderr
    assert "Traceback" not in done.stderr and "╭" not in done.stderr


def _interrupt_after(stage: str) -> Any:
    def run(*_: object, progress: Any, **__: object) -> None:
        progress("building the cell")
        progress(stage)
        raise KeyboardInterrupt

    return run


@pytest.mark.parametrize("command", ["detect", "weld"])
def test_ctrl_c_writes_the_partial_report_and_exits_130(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: str
) -> None:
    import importlib

    # where each command finds its stage: detect in the package, weld (both sides) as weld_part's side A
    module = importlib.import_module("cell.pipeline.turnover" if command == "weld" else "cell.pipeline")
    monkeypatch.setattr(module, command, _interrupt_after("aligning the welding map to the cloud"))
    report, log = tmp_path / "r.json", tmp_path / "run.log"
    code, _, err = invoke("--log-file", str(log), command, "fence1", "--json", str(report))
    assert code == 130, err
    assert err.strip().splitlines()[-1].startswith("exit 130: interrupted")
    data = json.loads(report.read_text())
    assert data["interrupted"]["stage"] == "aligning the welding map to the cloud"
    assert data["error"]["exit_code"] == 130 and data["scenario"] == "fence1" and data["seams"] == []
    assert data["provenance"]["seed"] == data["config"]["seed"]
    assert "building the cell" in log.read_text()


def test_quiet_keeps_progress_off_stderr_and_in_the_log(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from cell import pipeline

    monkeypatch.setattr(pipeline, "detect", _interrupt_after("splicing point clouds"))
    log = tmp_path / "run.log"
    code, _, err = invoke("-q", "--log-file", str(log), "detect", "fence1")
    assert code == 130
    assert "building the cell" not in err and "building the cell" in log.read_text()
    assert err.strip().splitlines() == ["exit 130: interrupted (Ctrl-C) during: splicing point clouds"]
    code, _, err = invoke("detect", "fence1")  # the next invocation starts from the defaults
    assert "building the cell" in err


def test_reports_are_written_whole_with_the_umask_permissions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import os

    from cell.errors import OutputError
    from cell.export.reports.report import write_json

    with pytest.raises(OutputError) as e:
        write_json(tmp_path / "sub" / "r.json", {})  # a missing folder is not made
    assert "'" + str(tmp_path / "sub") + "' does not exist" in e.value.message and not (tmp_path / "sub").exists()
    (tmp_path / "sub").mkdir()
    old = os.umask(0o027)
    try:
        p = write_json(tmp_path / "sub" / "r.json", {"a": 1})
    finally:
        os.umask(old)
    assert p.stat().st_mode & 0o777 == 0o640
    assert json.loads(p.read_text()) == {"a": 1}
    assert list((tmp_path / "sub").iterdir()) == [p]  # no temporary file left
    write_json("-", {"b": [1, 2]})
    assert json.loads(capsys.readouterr().out) == {"b": [1, 2]}
    with pytest.raises(OutputError) as e:
        write_json(p / "r.json", {})  # under a file
    assert e.value.path == str(p / "r.json") and ".part" not in e.value.message


def test_the_exit_line_names_lost_cameras_and_undone_seams() -> None:
    from cell.cli.printout.explain import detection_exit, weld_exit

    seams = [
        {"status": "found", "reason_code": None, "welded": True, "planned": True},
        {"status": "found", "reason_code": None, "welded": False, "weld_reason_code": "low_confidence"},
        {"status": "occluded", "reason_code": "occluded", "welded": False, "weld_reason_code": "not_located"},
        {"status": "not_visible", "reason_code": "underside", "welded": False, "weld_reason_code": "not_visible"},
    ]
    rep = {
        "seams": seams,
        "lost_cameras": ["cam_left: 0 valid pixels"],
        "error": None,
        "summary": {"found": 2, "visible": 3},
        "welded": 1,
    }
    assert detection_exit(rep) == (
        "exit 3: camera cam_left lost (0 valid pixels); 1 seam occluded (occluded: 1); 2/3 visible found"
    )
    assert weld_exit(rep) == (
        "exit 3: camera cam_left lost (0 valid pixels); 2 seams not welded (low_confidence: 1, not_located: 1);"
        " 1/3 welded"
    )


def test_the_exit_line_of_a_run_that_welded_everything_or_only_planned() -> None:
    from cell.cli.printout.explain import weld_exit

    welded = {"status": "found", "welded": True, "planned": True}
    rep = {"seams": [welded] * 2, "lost_cameras": ["cam_left: dead"], "error": None, "welded": 2}
    assert weld_exit(rep) == "exit 3: camera cam_left lost (dead); 2/2 welded"
    planned = {"status": "found", "welded": False, "planned": True, "weld_reason_code": "preview"}
    refused = {"status": "found", "welded": False, "planned": False, "weld_reason_code": "not_planned"}
    rep = {"seams": [planned, refused], "lost_cameras": [], "error": None, "welded": 0}
    assert weld_exit(rep) == "exit 3: 1 seam not planned (not_planned: 1); 1/2 planned"


def test_bench_writes_an_untracked_run_folder_by_default() -> None:
    import datetime as dt
    import subprocess

    from cell.cli.look import bench_folder

    folder = bench_folder(None, dt.datetime(2026, 1, 2, 3, 4, 5, tzinfo=dt.UTC))
    assert folder == Path("runs/bench-20260102T030405Z")
    assert bench_folder(Path("x")) == Path("x")
    ignored = subprocess.run(["git", "-C", str(REPO), "check-ignore", "-q", str(folder / "bench.json")], check=False)
    assert ignored.returncode == 0  # .gitignore has /runs/
