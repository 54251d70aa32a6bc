"""``cell weld``'s job journal (docs/journal.md): where it goes, the resume it continues (checked before any work),
its first and last records, and the report of a job stopped on the way, built from it."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cell.cli.common import detail, fail_line, warn
from cell.cli.outputs import STDOUT, Writer, check_file
from cell.errors import EXIT_INTERRUPTED, JournalError, JournalFault
from cell.journal import Interrupted, JobState, JournalWriter, read_journal

SUFFIX = ".journal.jsonl"
FOLDER_NAME = "job" + SUFFIX


def journal_path(explicit: Path | None, json_path: Path | None, program: Path | None) -> Path | None:
    """The journal's place: ``--journal``; else beside the ``--json`` report (``r.json`` -> ``r.journal.jsonl``);
    else ``job.journal.jsonl`` in the ``--program`` folder; else none (a job that writes nothing keeps no record)."""
    if explicit is not None:
        return explicit
    if json_path is not None and str(json_path) != STDOUT:
        return json_path.with_name(json_path.name.removesuffix(".json") + SUFFIX)
    return program / FOLDER_NAME if program is not None else None


def find_journal(path: Path) -> Path:
    """``--resume``'s journal: the file, or the one journal in the folder given. JournalError (exit 2) if none."""
    if not path.is_dir():
        return path
    found = sorted(path.glob("*" + SUFFIX))
    if len(found) != 1:
        what = "no journal" if not found else f"{len(found)} journals ({', '.join(p.name for p in found)})"
        raise JournalError(f"--resume {str(path)!r}: {what} in the folder; valid: one *{SUFFIX}", JournalFault.MISSING)
    return found[0]


def resumed(path: Path, prov: Mapping[str, Any]) -> JobState:
    """The interrupted job to continue, checked before any work: the same scenario, seed and map (by sha256) as
    this command's, and not finished. JournalError (exit 2) naming what differs."""
    state = read_journal(find_journal(path))
    for w in state.warnings:
        warn(w)
    start = state.start
    for key in ("scenario_sha256", "map_sha256", "seed"):
        if start.get(key) != prov.get(key):
            raise JournalError(
                f"--resume {str(state.path)!r}: a job of another {key.split('_')[0]} ({key} {start.get(key)!r}, "
                f"this command's {prov.get(key)!r}); valid: the journal of this scenario's job",
                JournalFault.OTHER_JOB,
            )
    if not state.resumable:
        end = state.end or {}
        raise JournalError(
            f"--resume {str(state.path)!r}: the job ended ({end.get('outcome')}, exit {end.get('exit_code')}) in run "
            f"{end.get('run')}; valid: the journal of a job stopped on the way",
            JournalFault.FINISHED,
        )
    return state


@dataclass
class JobLog:
    """The running job's journal: its writer, the job it resumes (None: a new job) and where it is."""

    writer: JournalWriter
    state: JobState | None

    @property
    def run(self) -> str:
        return self.writer.run

    def reread(self) -> JobState | None:
        """The journal as it stands (None when it cannot be read back: its folder removed meanwhile)."""
        try:
            return read_journal(self.writer.path)
        except JournalError as e:
            warn(f"the journal cannot be read back: {e.message}")
            return None


def joined(log: JobLog | None, on_b: bool) -> Callable[[dict[str, Any]], dict[str, Any]] | None:
    """How a finished run's report is joined with its journal (each seam's run, the earlier runs' welds)."""
    if log is None:
        return None

    def amend(rep: dict[str, Any]) -> dict[str, Any]:
        from cell.export.reports.journal_report import joined_report

        state = log.reread()
        return joined_report(rep, state, log.run, on_b=on_b) if state is not None else rep

    return amend


def open_job(
    path: Path | None, resume: JobState | None, prov: Mapping[str, Any], options: Mapping[str, Any]
) -> JobLog | None:
    """Start the journal (a new one, or the resumed job's, appended to) with the ``start`` record: scenario, seed,
    commit, command and the options. A new job would not replace the journal of a job that can still be resumed
    (JournalError, exit 2)."""
    if resume is not None:
        writer = JournalWriter(resume.path, resume.next_run())
    elif path is None:
        return None
    else:
        check_file(path, "--journal", stdout_ok=False)
        _replaceable(path)
        writer = JournalWriter.create(path)
    keys = ("scenario_file", "scenario_sha256", "map_file", "map_sha256", "seed", "commit", "command")
    writer.write(
        "start",
        resume_of=list(resume.runs) if resume is not None else [],
        scenario=options.get("scenario"),
        **{k: prov.get(k) for k in keys},
        options=dict(options),
    )
    detail(f"journal: {writer.path} (run {writer.run})")
    return JobLog(writer, resume)


def _replaceable(path: Path) -> None:
    """A journal already at ``path`` may be replaced by a new job only when its job ended."""
    if not path.exists() or path.stat().st_size == 0:
        return
    try:
        state = read_journal(path)
    except JournalError:
        return  # not a journal of a job: the output check allowed it as a file to write
    if state.resumable:
        raise JournalError(
            f"--journal {str(path)!r} holds a job stopped on the way (run {state.runs[-1]}); valid: --resume it, "
            "or remove the file",
            JournalFault.UNFINISHED,
        )


def end_job(log: JobLog | None, outcome: str, exit_code: int, message: str = "", **more: Any) -> None:
    """The journal's last record: the job's ``outcome`` (complete, partial, failed, interrupted), exit code, why."""
    if log is None:
        return
    log.writer.write("end", outcome=outcome, exit_code=exit_code, message=message, **more)
    log.writer.close()


def stopped(
    log: JobLog | None,
    e: BaseException,
    stage: str,
    base: Mapping[str, Any],
    writer: Writer,
    json_path: Path | None,
) -> int:
    """A job stopped on the way (a signal, an exception): the journal's ``end``, the report built from it (every
    stage and weld it holds), the last line; returns the exit code (128 + the signal; 1 for an exception)."""
    from cell.export.reports.journal_report import stopped_job_report

    if isinstance(e, Interrupted):
        code, why = e.exit_code, f"interrupted ({e.name})"
    elif isinstance(e, KeyboardInterrupt):
        code, why = EXIT_INTERRUPTED, "interrupted (Ctrl-C)"
    else:
        code, why = int(getattr(e, "exit_code", 1)), f"failed ({type(e).__name__}: {e})"
    outcome = "interrupted" if isinstance(e, KeyboardInterrupt) else "failed"
    end_job(log, outcome, code, f"{why} during: {stage}", stage=stage, signal=getattr(e, "name", None))
    rep = dict(base)
    rep["interrupted"] = {"stage": stage, "signal": getattr(e, "name", None)}
    rep["error"] = {"type": type(e).__name__, "message": f"{why} during: {stage}", "exit_code": code}
    state = log.reread() if log is not None else None
    if state is not None:
        rep = stopped_job_report(state, rep)
    writer.report(json_path, rep)
    done = f"; {rep.get('welded', 0)} seam(s) welded, journal {state.path}" if state is not None else ""
    where = f"; partial report in {json_path}" if json_path is not None and str(json_path) != STDOUT else ""
    fail_line(f"exit {code}: {why} during: {stage}{done}{where if not writer.failures else ''}")
    return code
