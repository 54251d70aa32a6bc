"""Outputs checked before the run and written whatever happens: a path that cannot be written (a device, a FIFO, a
socket, a folder where a file is asked for, a missing folder) is one line and exit 2 before any work, and the job
then holds every folder it writes into (a lock naming it, released when the command ends: :mod:`cell.outputs`);
each output is written on its own so a late failure loses only that one; and what Ctrl-C writes when the run had
not finished (docs/cli.md, "Outputs")."""

from __future__ import annotations

import contextlib
import shlex
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import typer

from cell import outputs
from cell.cli.bar import Bar
from cell.cli.common import detail, fail_line, results_to_stderr, say, warn
from cell.errors import EXIT_INTERRUPTED, EXIT_PARTIAL, EXIT_USAGE, OutputError, OutputFault

if TYPE_CHECKING:
    from cell.scenario import Scenario

STDOUT = "-"
T = TypeVar("T")


@dataclass
class _Held:
    """What this command holds: its folders' locks, and the folders it made for its outputs."""

    locks: dict[Path, outputs.FolderLock] = field(default_factory=dict)
    made: list[Path] = field(default_factory=list)

    def release(self) -> None:
        """Free every lock, then remove each folder made for this job that it left empty."""
        for lock in self.locks.values():
            lock.release()
        for folder in reversed(self.made):
            with contextlib.suppress(OSError):
                folder.rmdir()
        self.locks.clear()
        self.made.clear()


_held: _Held | None = None  # the running command's (None outside a command: the Python API holds nothing)


def begin_command() -> Callable[[], None]:
    """A command starts: what it will hold is recorded from now; the function returned releases it all (the root
    callback calls it when the command ends, however it ends; a killed process's locks are freed by the kernel)."""
    global _held
    if _held is not None:
        _held.release()
    held = _held = _Held()

    def end() -> None:
        global _held
        held.release()
        if _held is held:
            _held = None

    return end


def _command() -> str:
    """The job's command line, as a lock names it."""
    words = list(sys.argv)
    if words:
        words[0] = Path(words[0]).name
    return shlex.join(words)


def hold_folder(folder: Path, option: str) -> None:
    """Take ``folder``'s job lock for the rest of this command (once per folder; released when the command ends,
    however it ends). Outside a command (the Python API) nothing is held. OutputError (exit 2) naming the job
    that holds it."""
    if _held is None or folder in _held.locks:
        return
    lock = outputs.hold(folder, command=_command(), option=option)
    _held.locks[folder] = lock
    if lock.taken_over is not None:
        left = f"; removed {len(lock.removed)} half-written file(s) it left" if lock.removed else ""
        warn(f"{option}: took over the lock of a job that never ended in {str(folder)!r} "
             f"({lock.taken_over.describe()}: killed?){left}")  # fmt: skip
    detail(f"holding {folder / outputs.LOCK_NAME}")


def check_file(path: Path | None, option: str, *, stdout_ok: bool = True) -> None:
    """Before the run: ``path`` can be written as a regular file (``-`` is stdout where allowed; a link is written
    through to its target), and this job holds its folder. OutputError if not."""
    if path is None:
        return
    if str(path) == STDOUT:
        if not stdout_ok:
            raise OutputError(f"{option} cannot be '-' (standard output); valid: a file name", path=STDOUT,
                              code=OutputFault.STDOUT)  # fmt: skip
        results_to_stderr()
        return
    target = outputs.check_file(path, option)
    hold_folder(target.parent, option)


def check_folder(path: Path | None, option: str) -> None:
    """Before the run: ``path`` is a folder files can be written in, made now if missing (its parent must exist),
    and this job holds it. OutputError if not."""
    if path is None:
        return
    existed = outputs.resolve(path).is_dir()
    target = outputs.check_folder(path, option, create=True)
    if not existed and _held is not None:  # made for this job: gone again if the job ends without writing in it
        _held.made.append(target)
    hold_folder(target, option)


@dataclass
class Writer:
    """Writes each output on its own: a failure is reported (one line each) and the next output still written."""

    failures: list[OutputError] = field(default_factory=list)
    journal: Any = None  # the job's JournalWriter: each output written is an ``output`` record

    def written(self, what: str, paths: list[Path]) -> None:
        """Journal the outputs just written (nothing without a journal)."""
        if self.journal is not None and paths:
            self.journal.write("output", what=what, paths=[str(p) for p in paths])

    def attempt(self, what: Callable[[], T]) -> T | None:
        """Run one writing step; its OutputError (or any OSError) is kept, and None returned."""
        try:
            return what()
        except OutputError as e:
            self.failures.append(e)
        except OSError as e:
            self.failures.append(OutputError(f"cannot write {e.filename or 'an output'}: {e.strerror or e}"))
        fail_line(f"error: {self.failures[-1].message}")
        return None

    def report(self, path: Path | None, report: Mapping[str, Any]) -> None:
        """Write the JSON report (stdout for ``-``), if one was asked for."""
        if path is None:
            return
        from cell.export.reports.report import write_json

        if self.attempt(lambda: write_json(path, report)) is not None and str(path) != STDOUT:
            say(f"report written to {path}")
            self.written("report", [path])

    def explanation(self) -> str | None:
        """The last line when an output was lost, or None."""
        if not self.failures:
            return None
        lost = ", ".join(repr(e.path) if e.path else "an output" for e in self.failures)
        return f"exit {self.failures[0].exit_code}: could not write {lost}; every other output was written"


@dataclass
class Stage:
    """The progress callback of a run that remembers the last stage it reached (for Ctrl-C's report); its ``count``
    draws a stage's count (the planner's seams planned / total) as a bar on a terminal."""

    last: str = "starting"
    count: Bar = field(default_factory=Bar)

    def __call__(self, msg: str) -> None:
        self.last = msg
        say(msg)


def interrupted_report(
    scenario: Scenario, method: str | None, stage: str, provenance: Mapping[str, Any] | None
) -> dict[str, Any]:
    """The report of a run stopped by Ctrl-C before its stages returned: what ran, where it stopped, no seam
    results (docs/cli.md: ``interrupted``, ``error`` with exit code 130)."""
    return stopped_report(
        scenario.name,
        method or scenario.locator.method,
        stage,
        provenance,
        noise=scenario.noise,
        config=scenario.model_dump(mode="json"),
    )


def stopped_report(
    name: str,
    method: str,
    stage: str,
    provenance: Mapping[str, Any] | None,
    *,
    noise: str | None = None,
    frame: str = "R",
    config: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """The keys of every interrupted report (a scenario run's, or ``cell locate``'s without a scenario: no noise,
    no config, the cloud's frame)."""
    from cell.export.reports.report import REPORT_VERSION

    return {
        "report_version": REPORT_VERSION,
        "provenance": dict(provenance) if provenance is not None else None,
        "scenario": name,
        "method": method,
        "noise": noise,
        "frame": frame,
        "units": "m",
        "interrupted": {"stage": stage},
        "seams": [],
        "summary": None,
        "error": {
            "type": "KeyboardInterrupt",
            "message": f"interrupted (Ctrl-C) during: {stage}",
            "exit_code": EXIT_INTERRUPTED,
        },
        "config": dict(config) if config is not None else None,
    }


def on_interrupt(writer: Writer, path: Path | None, report: Mapping[str, Any], what: str) -> None:
    """Ctrl-C: write the report there is (marked ``interrupted``), say so on the last line."""
    rep = dict(report)
    rep.setdefault("interrupted", {"stage": what})
    writer.report(path, rep)
    detail(f"interrupted during: {what}")
    fail_line(
        f"exit {EXIT_INTERRUPTED}: interrupted (Ctrl-C) during: {what}"
        + (f"; partial report in {path}" if path is not None and str(path) != STDOUT and not writer.failures else "")
    )


def finish(writer: Writer, partial: str | None) -> None:
    """End a command: the partial run's explanation, then any lost output's (exit 2 wins: an output is gone);
    exit 3 when only partial; return when everything asked for was done."""
    if partial is not None:
        fail_line(partial)
    lost = writer.explanation()
    if lost is not None:
        fail_line(lost)
        raise typer.Exit(EXIT_USAGE)
    if partial is not None:
        raise typer.Exit(EXIT_PARTIAL)
