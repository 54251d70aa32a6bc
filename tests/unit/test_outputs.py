"""Outputs: only regular files are written (a device, a FIFO, a socket, a folder, a missing folder refused with its
code), a symbolic link is written through to its target and stays a link, and every file is written whole (a
failure or a kill mid-write leaves the old file)."""

from __future__ import annotations

import errno
import os
import signal
import socket
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from cell.errors import OutputError, OutputFault
from cell.outputs import LOCK_NAME, check_file, check_folder, leftovers, replacing, write_atomic, write_text


class expect:  # noqa: N801 - reads as a verb: with expect(code, needles): ...
    """The block raises an OutputError with this code, its one line naming the path and what is valid."""

    def __init__(self, code: OutputFault, *needles: str) -> None:
        self.code, self.needles = code, needles

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None, tb: object) -> bool:
        assert isinstance(value, OutputError), f"no OutputError: {value!r}"
        assert value.code is self.code, value.message
        assert "\n" not in value.message, value.message
        assert ("valid:" if self.code is not OutputFault.WRITE_FAILED else "left as it was") in value.message
        for n in self.needles:
            assert n in value.message, value.message
        return True


def test_a_new_file_in_an_existing_folder_is_written_whole_with_the_umask(tmp_path: Path) -> None:
    old = os.umask(0o027)
    try:
        p = write_text(tmp_path / "r.json", "{}\n")
    finally:
        os.umask(old)
    assert p.read_text() == "{}\n" and p.stat().st_mode & 0o777 == 0o640
    assert os.listdir(tmp_path) == ["r.json"]  # no temporary file left


def test_a_replaced_file_keeps_its_permissions(tmp_path: Path) -> None:
    p = tmp_path / "k.src"
    p.write_text("old")
    p.chmod(0o600)
    write_text(p, "new")
    assert p.read_text() == "new" and stat.S_IMODE(p.stat().st_mode) == 0o600


def test_a_folder_is_refused_as_a_file(tmp_path: Path) -> None:
    with expect(OutputFault.FOLDER, "is a folder", str(tmp_path)):
        check_file(tmp_path, "--json")
    assert tmp_path.is_dir()


def test_a_fifo_is_refused_and_stays_a_fifo(tmp_path: Path) -> None:
    fifo = tmp_path / "r.json"
    os.mkfifo(fifo)
    with expect(OutputFault.FIFO, "FIFO", "--json"):
        check_file(fifo, "--json")
    with expect(OutputFault.FIFO, "FIFO"):
        write_atomic(fifo, b"{}")  # the writer checks too: it never blocks on the pipe nor replaces it
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and leftovers(tmp_path) == []


def test_a_socket_is_refused_and_stays_a_socket(tmp_path: Path) -> None:
    path = tmp_path / "s"
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
        s.bind(str(path))
        with expect(OutputFault.SOCKET, "socket"):
            check_file(path, "--json")
        with expect(OutputFault.SOCKET):
            write_atomic(path, b"{}")
    assert stat.S_ISSOCK(os.lstat(path).st_mode)


def test_a_device_is_refused_and_stays_a_device(tmp_path: Path) -> None:
    with expect(OutputFault.DEVICE, "'/dev/null'", "character device"):
        check_file(Path("/dev/null"), "--json")  # checked only: a test never writes to a real device
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    link = tmp_path / "r.json"
    link.symlink_to("/dev/null")
    with expect(OutputFault.DEVICE, "a link to '/dev/null'"):
        check_file(link, "--json")
    assert link.is_symlink() and os.readlink(link) == "/dev/null"


def test_a_missing_folder_is_refused_and_not_made(tmp_path: Path) -> None:
    gone = tmp_path / "no" / "dir"
    with expect(OutputFault.NO_FOLDER, str(gone), "does not exist"):
        check_file(gone / "r.json", "--json")
    with expect(OutputFault.NO_FOLDER):
        write_atomic(gone / "r.json", b"{}")
    assert not (tmp_path / "no").exists()
    with expect(OutputFault.NO_FOLDER, str(tmp_path / "no")):
        check_folder(gone, "--program", create=True)  # only the last folder is ever made
    assert not (tmp_path / "no").exists()
    assert check_folder(tmp_path / "new", "--program", create=True).is_dir()


def test_a_file_is_refused_as_a_folder(tmp_path: Path) -> None:
    f = tmp_path / "k"
    f.write_text("x")
    with expect(OutputFault.NOT_A_FOLDER, "not a folder"):
        check_folder(f, "--program", create=True)
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with expect(OutputFault.NOT_A_FOLDER, "FIFO"):
        check_folder(fifo, "--program")
    assert f.read_text() == "x" and stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_a_link_is_written_through_to_its_target_and_stays_a_link(tmp_path: Path) -> None:
    (tmp_path / "runs").mkdir()
    target = tmp_path / "runs" / "r1.json"
    target.write_text("old")
    link = tmp_path / "latest.json"
    link.symlink_to(Path("runs") / "r1.json")
    assert check_file(link, "--json") == target.resolve()
    write_text(link, "new")
    assert link.is_symlink() and os.readlink(link) == str(Path("runs") / "r1.json")
    assert target.read_text() == "new" and leftovers(tmp_path / "runs") == [] and leftovers(tmp_path) == []
    dangling = tmp_path / "next.json"
    dangling.symlink_to(Path("runs") / "r2.json")
    write_text(dangling, "made")  # a dangling link: its target is made, in the target's existing folder
    assert dangling.is_symlink() and (tmp_path / "runs" / "r2.json").read_text() == "made"
    folder_link = tmp_path / "out"
    folder_link.symlink_to("runs")
    assert check_folder(folder_link, "--program") == (tmp_path / "runs").resolve()


def test_a_loop_of_links_and_the_lock_name_are_refused(tmp_path: Path) -> None:
    (tmp_path / "a").symlink_to("b")
    (tmp_path / "b").symlink_to("a")
    with expect(OutputFault.LINK_LOOP, "loop"):
        check_file(tmp_path / "a", "--json")
    with expect(OutputFault.RESERVED, LOCK_NAME):
        check_file(tmp_path / LOCK_NAME, "--json")


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write any file")
def test_a_read_only_file_is_refused(tmp_path: Path) -> None:
    p = tmp_path / "r.json"
    p.write_text("mine")
    p.chmod(0o444)
    with expect(OutputFault.NOT_WRITABLE, "read-only"):
        check_file(p, "--json")


def test_a_failure_mid_write_leaves_the_old_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    p = tmp_path / "trajectory.csv"
    p.write_text("the whole old file\n")
    with expect(OutputFault.WRITE_FAILED, str(p), "No space left"), replacing(p, what="trajectory") as tmp:
        tmp.write_text("half of the new")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert p.read_text() == "the whole old file\n" and os.listdir(tmp_path) == ["trajectory.csv"]

    def full(fd: int) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)  # the data written, the flush to the disk fails
    with expect(OutputFault.WRITE_FAILED, "report"):
        write_atomic(p, b"new" * 1000, what="report")
    assert p.read_text() == "the whole old file\n" and os.listdir(tmp_path) == ["trajectory.csv"]


def test_what_another_puts_at_the_path_meanwhile_is_never_replaced(tmp_path: Path) -> None:
    p = tmp_path / "r.json"
    with expect(OutputFault.FIFO), replacing(p) as tmp:
        tmp.write_text("{}")
        os.mkfifo(p)  # between the check before the run and the rename
    assert stat.S_ISFIFO(os.lstat(p).st_mode) and leftovers(tmp_path) == []


KILLED_MID_WRITE = """
import os, signal, sys
from cell.outputs import replacing
with replacing(sys.argv[1]) as tmp, open(tmp, "wb") as f:
    f.write(b"x" * 100_000)
    f.flush()
    os.kill(os.getpid(), signal.SIGKILL)
"""


def test_a_kill_mid_write_leaves_the_old_file_whole(tmp_path: Path) -> None:
    p = tmp_path / "trajectory_A.json"
    p.write_text('{"points": []}')
    done = subprocess.run([sys.executable, "-c", KILLED_MID_WRITE, str(p)], check=False)
    assert done.returncode == -signal.SIGKILL
    assert p.read_text() == '{"points": []}'
    (left,) = leftovers(tmp_path)  # the half-written temporary file, under its own name
    assert left.name.startswith(".trajectory_A.json.") and left.stat().st_size == 100_000
