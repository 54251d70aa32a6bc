"""Outputs checked before the run and written whatever happens: a path that cannot be written is one line and exit 2
before any capture (a probe file, since permission bits alone do not say), each output written on its own so a late
failure loses only that one, and what Ctrl-C writes when the run had not finished (docs/cli.md)."""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import typer

from cell.cli.bar import Bar
from cell.cli.common import detail, fail_line, results_to_stderr, say
from cell.errors import EXIT_INTERRUPTED, EXIT_PARTIAL, EXIT_USAGE, OutputError

if TYPE_CHECKING:
    from cell.scenario import Scenario

STDOUT = "-"
T = TypeVar("T")


def _absolute(path: Path) -> Path:
    return path if path.is_absolute() else Path.cwd() / path


def _probe(path: Path, option: str, shown: Path) -> None:
    """``path`` or its first existing ancestor must be a folder a file can be created in."""
    anc = path
    while not anc.exists() and anc != anc.parent:
        anc = anc.parent
    if not anc.is_dir():
        raise OutputError(f"{option} {str(shown)!r}: {str(anc)!r} is a file, not a folder", path=str(shown))
    try:
        with tempfile.TemporaryFile(dir=anc):
            pass
    except OSError as e:
        raise OutputError(
            f"{option} {str(shown)!r}: cannot write in {str(anc)!r} ({e.strerror or e})", path=str(shown)
        ) from None


def check_file(path: Path | None, option: str, *, stdout_ok: bool = True) -> None:
    """Before the run: ``path`` can be written as a file (``-`` is stdout where allowed). OutputError if not."""
    if path is None:
        return
    if str(path) == STDOUT:
        if not stdout_ok:
            raise OutputError(f"{option} cannot be '-' (standard output)", path=STDOUT)
        results_to_stderr()
        return
    p = _absolute(path)
    if p.is_dir():
        raise OutputError(f"{option} {str(path)!r} is a folder; give a file name", path=str(path))
    if p.exists():
        try:
            with p.open("ab"):
                pass
        except OSError as e:
            raise OutputError(f"{option} {str(path)!r} cannot be written ({e.strerror or e})", path=str(path)) from None
    _probe(p.parent, option, path)


def check_folder(path: Path | None, option: str) -> None:
    """Before the run: ``path`` is (or can be created as) a folder files can be written in. OutputError if not."""
    if path is None:
        return
    p = _absolute(path)
    if p.exists() and not p.is_dir():
        raise OutputError(f"{option} {str(path)!r} is a file, not a folder", path=str(path))
    _probe(p, option, path)


@dataclass
class Writer:
    """Writes each output on its own: a failure is reported (one line each) and the next output still written."""

    failures: list[OutputError] = field(default_factory=list)

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
        from cell.export.report import write_json

        if self.attempt(lambda: write_json(path, report)) is not None and str(path) != STDOUT:
            say(f"report written to {path}")

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
    from cell.export.report import REPORT_VERSION

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
