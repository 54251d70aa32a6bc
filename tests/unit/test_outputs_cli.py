"""Every command's outputs at a path that is not a regular file (or a folder, for a folder option), in a missing
folder or in a folder another job holds: exit 2 with one line naming the path and what is valid, before any work;
the FIFO still a FIFO, the link still a link. A link to a file is written through; the lock goes with the job."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cell.cli import app
from cell.outputs import LOCK_NAME

runner = CliRunner()

# (command line before the option, option): each command with each of its outputs
OUTPUTS = [
    (["weld", "fence1"], "--json"),
    (["weld", "fence1"], "--program"),
    (["weld", "fence1"], "--krl"),
    (["weld", "fence1"], "--html"),
    (["preview", "fence1"], "--out"),
    (["rescan", "fence1"], "--json"),
    (["detect", "fence1"], "--json"),
    (["detect", "fence1"], "--save-cloud"),
    (["locate", "cloud.ply", "--map", "maps/fence1.dxf"], "--json"),
    (["locate", "cloud.ply", "--map", "maps/fence1.dxf"], "--save-cloud"),
    (["capture", "fence1"], "--out"),
    (["bench", "fence1"], "--out"),
    (["sweep", "fence1"], "--out"),
]
FOLDER_OPTIONS = {"--program", "--krl", "--out"}


def run(*args: str) -> tuple[int, str]:
    result = runner.invoke(app, list(args))
    return result.exit_code, result.stderr


def one_line_refusal(code: int, stderr: str, *needles: str) -> str:
    """Exit 2, one ``error:`` line naming ``needles`` and what is valid, nothing done before it."""
    assert code == 2, stderr
    lines = [ln for ln in stderr.strip().splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("error:")]
    assert len(errors) == 1 and lines[-1] == errors[0], stderr
    assert "valid:" in errors[0] and "Traceback" not in stderr
    assert not any(ln.startswith("·") for ln in lines), stderr  # no progress line: no work began
    for n in needles:
        assert n in errors[0], errors[0]
    return errors[0]


@pytest.mark.parametrize(("command", "option"), OUTPUTS, ids=[f"{c[0]} {o}" for c, o in OUTPUTS])
def test_a_fifo_is_refused_before_any_work(tmp_path: Path, command: list[str], option: str) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    code, err = run(*command, option, str(fifo))
    kind = "not a folder" if option in FOLDER_OPTIONS else "not a regular file"
    named = "--program" if option == "--krl" else option  # the deprecated name's errors name the option to use
    one_line_refusal(code, err, named, str(fifo), "FIFO", kind)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and sorted(os.listdir(tmp_path)) == ["pipe"]


def test_a_socket_a_device_link_a_folder_and_a_missing_folder_are_refused(tmp_path: Path) -> None:
    import socket

    with socket.socket(socket.AF_UNIX) as s:
        s.bind(str(tmp_path / "sock"))
        one_line_refusal(*run("detect", "fence1", "--json", str(tmp_path / "sock")), "socket")
    assert stat.S_ISSOCK(os.lstat(tmp_path / "sock").st_mode)
    dev = tmp_path / "r.json"
    dev.symlink_to("/dev/null")  # a device reached through a link: refused, never written to
    one_line_refusal(*run("weld", "fence1", "--json", str(dev)), "a link to '/dev/null'", "character device")
    assert dev.is_symlink() and stat.S_ISCHR(os.stat(dev).st_mode)
    one_line_refusal(*run("detect", "fence1", "--json", str(tmp_path)), "is a folder")
    gone = tmp_path / "no" / "dir"
    one_line_refusal(*run("weld", "fence1", "--json", str(gone / "r.json")), f"'{gone}' does not exist")
    one_line_refusal(*run("weld", "fence1", "--program", str(gone)), f"'{gone.parent}' does not exist")
    assert not (tmp_path / "no").exists()
    (tmp_path / "k").write_text("a file")
    one_line_refusal(*run("weld", "fence1", "--krl", str(tmp_path / "k")), "--program", "is a file, not a folder")


HOLDER = """
import sys, time
from cell.outputs import hold
lock = hold(sys.argv[1], command="cell weld fence1 --json r.json --program k")
print("held", flush=True)
time.sleep(60)
"""


@pytest.mark.parametrize("option", ["--json", "--program"])
def test_a_folder_another_job_holds_is_refused_naming_it(tmp_path: Path, option: str) -> None:
    proc = subprocess.Popen([sys.executable, "-c", HOLDER, str(tmp_path)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
        path = tmp_path / "r.json" if option == "--json" else tmp_path
        code, err = run("weld", "fence1", option, str(path))
        one_line_refusal(code, err, option, "held by another job", f"pid {proc.pid},", "--program k'")
    finally:
        proc.kill()
        proc.wait(timeout=30)
        assert proc.stdout is not None
        proc.stdout.close()
    assert not (tmp_path / "r.json").exists()


def test_a_folder_made_for_a_job_that_fails_first_is_removed_with_its_lock(tmp_path: Path) -> None:
    made = tmp_path / "programs"
    code, err = run("weld", "no-such-scenario", "--program", str(made), "--json", str(tmp_path / "r.json"))
    assert code == 10, err  # the scenario is read after the outputs are checked and held
    assert not made.exists() and os.listdir(tmp_path) == []  # no empty folder, no lock file left


def test_a_link_is_written_through_and_the_lock_released(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from cell import pipeline

    def interrupted(*_: object, progress: object, **__: object) -> None:
        assert (tmp_path / "runs" / LOCK_NAME).exists()  # held while the job runs, in the folder written
        assert not (tmp_path / LOCK_NAME).exists()  # the link's folder: nothing is written there
        raise KeyboardInterrupt

    monkeypatch.setattr(pipeline, "detect", interrupted)
    (tmp_path / "runs").mkdir()
    (tmp_path / "runs" / "r1.json").write_text("{}")
    link = tmp_path / "latest.json"
    link.symlink_to(Path("runs") / "r1.json")
    code, err = run("detect", "fence1", "--json", str(link))
    assert code == 130, err  # Ctrl-C's report is written, through the link
    assert link.is_symlink() and os.readlink(link) == str(Path("runs") / "r1.json")
    assert json.loads((tmp_path / "runs" / "r1.json").read_text())["error"]["exit_code"] == 130
    assert sorted(os.listdir(tmp_path / "runs")) == ["r1.json"]  # the lock gone with the job, no temporary file


def test_a_log_file_that_is_a_fifo_is_refused_instead_of_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "run.log"
    os.mkfifo(fifo)
    code, err = run("--log-file", str(fifo), "detect", "fence1")
    one_line_refusal(code, err, "--log-file", "FIFO")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
