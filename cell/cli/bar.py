"""A count drawn as a bar on stderr (``rich.progress``) when stderr is a terminal, plain progress lines otherwise
(a log, a pipe, CI): the ``count(what, done, total)`` a stage's progress callable may carry (the planner's seams
planned / total, :func:`cell.pipeline.progress.seam_counter`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from cell.cli.common import err, log, say, settings


@dataclass
class Bar:
    """One bar at a time: a new ``what`` (or a count back at 0) starts a new one; done == total ends it. Plain
    lines at every tenth when stderr is no terminal; nothing with --quiet (the log file still gets the lines)."""

    _progress: Any = None
    _task: Any = None
    _what: str = ""
    _tenth: int = -1
    _log_tenth: int = field(default=-1)

    def __call__(self, what: str, done: int, total: int) -> None:
        tenth = 10 * done // max(total, 1)
        if tenth > self._log_tenth or done >= total:
            self._log_tenth = tenth
            log.info(f"{what}: {done}/{total}")
        if settings.quiet:
            return
        if not err.is_terminal:
            if what != self._what or tenth > self._tenth or done >= total:
                self._what, self._tenth = what, tenth
                say(f"{what}: {done}/{total}")
            if done >= total:
                self._what, self._tenth, self._log_tenth = "", -1, -1
            return
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        if self._progress is None or what != self._what:
            self.close()
            self._progress = Progress(
                TextColumn("[dim]· {task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=err,
                transient=False,
            )
            self._progress.start()
            self._task = self._progress.add_task(what, total=total)
            self._what = what
        self._progress.update(self._task, completed=done, total=total)
        if done >= total:
            self.close()

    def close(self) -> None:
        """Stop the bar being drawn (idempotent)."""
        if self._progress is not None:
            self._progress.stop()
        self._progress, self._task, self._what, self._tenth, self._log_tenth = None, None, "", -1, -1
