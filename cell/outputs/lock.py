"""One job at a time per output folder: a lock file ``.cell.lock`` in the folder, held with ``flock`` for as long as
the job runs and naming the job (pid, host, command, start time) so that a second job's refusal says who holds it.
The kernel drops a ``flock`` when its process ends however it ends, so a killed job's lock is free: the next job
takes it over (and is told so); a lock still held although the job it names is gone (a child it left) is broken.
A job that ends removes its lock file (docs/cli.md, "Outputs")."""

from __future__ import annotations

import contextlib
import datetime as dt
import fcntl
import json
import os
import socket
import stat
from dataclasses import dataclass, field
from pathlib import Path

from cell.errors import OutputError, OutputFault
from cell.outputs.paths import LOCK_NAME
from cell.outputs.whole import leftovers

_TRIES = 8  # a lock file removed or broken while being taken: try again (each round is one system call or two)


@dataclass(frozen=True)
class Holder:
    """The job a lock names."""

    pid: int
    host: str
    command: str
    started_utc: str

    @classmethod
    def me(cls, command: str) -> Holder:
        now = dt.datetime.now(dt.UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z")
        return cls(os.getpid(), socket.gethostname(), command, now)

    def describe(self) -> str:
        where = "" if self.host == socket.gethostname() else f" on {self.host}"
        return f"pid {self.pid}{where}, {self.command!r}, started {self.started_utc}"

    def gone(self) -> bool:
        """Its process no longer exists (known only on this host; elsewhere it is taken to be running)."""
        if self.host != socket.gethostname():
            return False
        try:
            os.kill(self.pid, 0)
        except ProcessLookupError:
            return True
        except PermissionError:  # another user's live process
            return False
        return False


def _read(fd: int) -> Holder | None:
    """The holder written in an open lock file, or None (empty, or not the cell's)."""
    try:
        data = json.loads(os.pread(fd, 4096, 0).decode("utf-8"))
        return Holder(int(data["pid"]), str(data["host"]), str(data["command"]), str(data["started_utc"]))
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _same_file(fd: int, path: Path) -> bool:
    try:
        a, b = os.fstat(fd), os.stat(path, follow_symlinks=False)
    except OSError:
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


@dataclass
class FolderLock:
    """A job's hold on an output folder; :meth:`release` (idempotent) removes the lock file and frees it.

    taken_over : the job whose lock this one took over (killed before it ended), or None.
    removed : the temporary files that job left half-written and this one removed.
    """

    folder: Path
    holder: Holder
    taken_over: Holder | None = None
    removed: tuple[Path, ...] = ()
    _fd: int | None = field(default=None, repr=False)

    @property
    def path(self) -> Path:
        return self.folder / LOCK_NAME

    def release(self) -> None:
        fd, self._fd = self._fd, None
        if fd is None:
            return
        try:
            if _same_file(fd, self.path):
                with contextlib.suppress(OSError):
                    os.unlink(self.path)  # while still locked: the next job cannot lock a file on its way out
        finally:
            os.close(fd)


def _refuse(folder: Path, option: str, why: str, code: OutputFault) -> OutputError:
    return OutputError(f"{option}: the folder {str(folder)!r} {why}", path=str(folder), code=code)


def _open(path: Path, folder: Path, option: str) -> int:
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
    except OSError as e:
        raise _refuse(folder, option, f"cannot hold a job lock ({LOCK_NAME}: {e.strerror or e}); valid: a "
                      "folder you can write in", OutputFault.NOT_WRITABLE) from None  # fmt: skip
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise _refuse(folder, option, f"has a {LOCK_NAME} that is not a regular file; valid: remove it",
                      OutputFault.RESERVED)  # fmt: skip
    return fd


def hold(folder: str | Path, *, command: str, option: str = "output") -> FolderLock:
    """Take ``folder``'s lock for this job (``command`` names it), or OutputError (code ``held``) naming the job
    that holds it. A free lock file left by a killed job is taken over, with the half-written files it left."""
    d = Path(folder)
    path = d / LOCK_NAME
    for _ in range(_TRIES):
        fd = _open(path, d, option)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            other = _read(fd)
            if other is not None and other.gone() and _same_file(fd, path):
                with contextlib.suppress(OSError):  # a child of a gone job holds it: break the lock, start anew
                    os.unlink(path)
                os.close(fd)
                continue
            os.close(fd)
            who = other.describe() if other is not None else "a job that did not say which"
            raise _refuse(d, option, f"is held by another job ({who}); valid: wait for it to end, or another "
                          "folder", OutputFault.HELD) from None  # fmt: skip
        if not _same_file(fd, path):  # its holder removed it as we locked it: lock the new one
            os.close(fd)
            continue
        before = _read(fd)
        me = Holder.me(command)
        text = json.dumps(me.__dict__).encode("utf-8") + b"\n"
        os.ftruncate(fd, 0)
        os.pwrite(fd, text, 0)
        os.fsync(fd)
        removed: list[Path] = []
        if before is not None:  # a job that never ended: what it was writing is half a file
            for p in leftovers(d):
                with contextlib.suppress(OSError):
                    p.unlink()
                    removed.append(p)
        return FolderLock(d, me, before, tuple(removed), fd)
    raise _refuse(d, option, f"has a {LOCK_NAME} that keeps changing; valid: try again", OutputFault.HELD)
