"""One job at a time per output folder: a second holder is refused with the first one named; a lock left by a killed
job is taken over (with the half-written files it left); a job that ends leaves no lock file."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from cell.errors import OutputError, OutputFault
from cell.outputs import LOCK_NAME, hold, leftovers

HOLDER = """
import sys, time
from cell.outputs import hold
lock = hold(sys.argv[1], command="cell weld fence1 --json r.json")
print("held", flush=True)
time.sleep(60)
"""

HALF_WRITTEN = """
import os, signal, sys
from cell.outputs import hold, replacing
lock = hold(sys.argv[1], command="cell weld fence1 --program k")
with replacing(os.path.join(sys.argv[1], "WELD_FENCE1.src")) as tmp, open(tmp, "wb") as f:
    f.write(b"DEF WELD_FENCE1()")
    f.flush()
    os.kill(os.getpid(), signal.SIGKILL)
"""


@contextmanager
def child(script: str, folder: Path) -> Iterator[subprocess.Popen[str]]:
    """A python process running ``script`` on ``folder``, stopped (SIGKILL) when the block ends."""
    proc = subprocess.Popen([sys.executable, "-c", script, str(folder)], stdout=subprocess.PIPE, text=True)
    try:
        yield proc
    finally:
        proc.kill()
        proc.wait(timeout=30)
        assert proc.stdout is not None
        proc.stdout.close()


def test_a_second_holder_is_refused_naming_the_first(tmp_path: Path) -> None:
    first = hold(tmp_path, command="cell detect fence1 --json r.json", option="--json")
    with pytest.raises(OutputError) as e:
        hold(tmp_path, command="cell weld fence1 --json r.json", option="--json")
    assert e.value.code is OutputFault.HELD and e.value.exit_code == 2
    msg = e.value.message
    assert f"pid {os.getpid()}" in msg and "'cell detect fence1 --json r.json'" in msg and str(tmp_path) in msg
    assert "started 20" in msg and "valid:" in msg and "\n" not in msg
    first.release()
    assert not (tmp_path / LOCK_NAME).exists()  # a job that ends leaves no lock file
    second = hold(tmp_path, command="cell weld fence1 --json r.json")
    assert second.taken_over is None  # released properly: nothing to take over
    second.release()
    second.release()  # idempotent


def test_a_holder_in_another_process_is_named_and_its_killed_lock_taken_over(tmp_path: Path) -> None:
    with child(HOLDER, tmp_path) as proc:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
        with pytest.raises(OutputError) as e:
            hold(tmp_path, command="cell weld fence1")
        assert e.value.code is OutputFault.HELD
        assert f"pid {proc.pid}," in e.value.message and "cell weld fence1 --json r.json" in e.value.message
    # SIGKILL: the kernel freed the flock, the lock file still names the dead job
    assert json.loads((tmp_path / LOCK_NAME).read_text())["pid"] == proc.pid
    lock = hold(tmp_path, command="cell weld fence1")
    assert lock.taken_over is not None and lock.taken_over.pid == proc.pid
    assert json.loads((tmp_path / LOCK_NAME).read_text())["pid"] == os.getpid()
    lock.release()


def test_taking_over_a_killed_job_removes_its_half_written_files(tmp_path: Path) -> None:
    (tmp_path / "notes.part").write_text("not ours")  # a user's file that only looks alike: kept
    done = subprocess.run([sys.executable, "-c", HALF_WRITTEN, str(tmp_path)], check=False)
    assert done.returncode == -signal.SIGKILL
    (left,) = leftovers(tmp_path)
    lock = hold(tmp_path, command="cell weld fence1 --program k")
    assert lock.taken_over is not None and lock.taken_over.command == "cell weld fence1 --program k"
    assert lock.removed == (left,) and not left.exists() and (tmp_path / "notes.part").exists()
    assert not (tmp_path / "WELD_FENCE1.src").exists()  # never half a program under its real name
    lock.release()


BROKEN = """
import fcntl, json, os, socket, sys, time
fd = os.open(os.path.join(sys.argv[1], ".cell.lock"), os.O_RDWR | os.O_CREAT)
fcntl.flock(fd, fcntl.LOCK_EX)
gone = int(sys.argv[2])
os.write(fd, json.dumps({"pid": gone, "host": socket.gethostname(), "command": "cell weld x",
                         "started_utc": "2026-01-01T00:00:00Z"}).encode())
print("held", flush=True)
time.sleep(60)
"""


def test_a_lock_still_held_for_a_job_that_is_gone_is_broken(tmp_path: Path) -> None:
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    gone = int(dead.stdout)  # a pid whose process has ended (a child of the job would still hold the flock)
    proc = subprocess.Popen([sys.executable, "-c", BROKEN, str(tmp_path), str(gone)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
        lock = hold(tmp_path, command="cell weld fence1")
        assert lock.taken_over is None  # a fresh lock file: the old one (still flocked by the orphan) unlinked
        assert json.loads((tmp_path / LOCK_NAME).read_text())["pid"] == os.getpid()
        lock.release()
    finally:
        proc.kill()
        proc.wait(timeout=30)
        assert proc.stdout is not None
        proc.stdout.close()


def test_a_lock_file_that_is_not_a_file_is_refused(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / LOCK_NAME)
    with pytest.raises(OutputError) as e:
        hold(tmp_path, command="cell weld fence1")
    assert e.value.code is OutputFault.RESERVED and LOCK_NAME in e.value.message
