"""The journal's writer: one JSON object per line, appended, flushed and fsynced before the job goes on, so a
killed process leaves every record written whole but (at worst) the last one."""

from __future__ import annotations

import json
import os
import signal
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

FORMAT = "cell-journal"
VERSION = 1
HOOK_ENV = "CELL_JOURNAL_SIGNAL"  # tests and benchmarks: a signal sent at a named record (docs/journal.md)


class JournalWriter:
    """Appends records to one journal file for one run of a job (``run``: ``r1``, ``r2`` ... for each resume).

    Every record carries the run, a sequence number within the journal, the wall time (UTC, ISO 8601) and its
    ``kind``; the fields are the caller's (JSON values). A new journal starts with the ``journal`` header."""

    def __init__(self, path: Path, run: str, *, seq: int = 0) -> None:
        self.path = Path(path)
        self.run = run
        self._seq = seq
        self._hook = _parse_hook(os.environ.get(HOOK_ENV, ""))
        fresh = not self.path.exists() or self.path.stat().st_size == 0
        flags = os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_CLOEXEC", 0)
        self._fd: int | None = os.open(self.path, flags, 0o644)
        if fresh:
            self.write("journal", format=FORMAT, version=VERSION)

    @classmethod
    def create(cls, path: Path, run: str = "r1") -> JournalWriter:
        """A new journal at ``path`` (one there already is replaced: the caller checked it holds no unfinished
        job)."""
        Path(path).unlink(missing_ok=True)
        return cls(path, run)

    def write(self, kind: str, **fields: Any) -> None:
        """Append one record and make it durable (flush and fsync) before returning."""
        if self._fd is None:
            return
        self._seq += 1
        rec: dict[str, Any] = {"kind": kind, "run": self.run, "seq": self._seq, "at": _now()}
        rec.update(fields)
        line = (json.dumps(rec, separators=(",", ":"), allow_nan=False, default=_plain) + "\n").encode()
        view = memoryview(line)
        while view:
            view = view[os.write(self._fd, view) :]
        os.fsync(self._fd)
        self._fire(kind, fields)

    def close(self) -> None:
        """Close the file (idempotent)."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def _fire(self, kind: str, fields: Mapping[str, Any]) -> None:
        """The test hook: ``KIND[:SEAM][@N]=SIGNAL`` sends SIGNAL to this process once the N-th (default first)
        record of that kind (for that seam) is on disk."""
        if self._hook is None:
            return
        want_kind, want_seam, nth, signum = self._hook
        if kind != want_kind or (want_seam and fields.get("seam") != want_seam):
            return
        self._hook = (want_kind, want_seam, nth - 1, signum) if nth > 1 else None
        if nth == 1:
            os.kill(os.getpid(), signum)


def _parse_hook(text: str) -> tuple[str, str, int, int] | None:
    """``KIND[:SEAM][@N]=SIGNAL`` (SIGNAL by name: ``SIGTERM``, ``TERM``) or None when unset or malformed."""
    if "=" not in text:
        return None
    what, name = text.rsplit("=", 1)
    nth = 1
    if "@" in what:
        what, n = what.rsplit("@", 1)
        nth = int(n) if n.isdigit() and int(n) > 0 else 1
    kind, _, seam = what.partition(":")
    name = name.strip().upper()
    sig = getattr(signal, name if name.startswith("SIG") else f"SIG{name}", None)
    return (kind, seam, nth, int(sig)) if sig is not None and kind else None


def _now() -> str:
    t = time.time()
    return time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(t)) + f".{int(t % 1 * 1000):03d}Z"


def _plain(value: Any) -> Any:
    """numpy scalars and arrays, tuples and paths as JSON values."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not a JSON value: {type(value).__name__}")


class SideLog:
    """A journal seen from one side of the part (``"A"``, ``"B"``): each record it writes names the side; with no
    journal (the Python API, a preview) it writes nothing."""

    def __init__(self, journal: JournalWriter | None, side: str = "A") -> None:
        self.journal = journal
        self.side = side

    def write(self, kind: str, **fields: Any) -> None:
        """Append one record naming this side (nothing without a journal)."""
        if self.journal is not None:
            self.journal.write(kind, side=self.side, **fields)

    def on(self, side: str) -> SideLog:
        """The same journal seen from ``side``."""
        return SideLog(self.journal, side)


NO_LOG = SideLog(None)
