"""How a stage reports progress: a callable taking one message (the CLI prints them on stderr), quiet by default.

Its own module so that paths which never build a simulated cell (``cell locate``, a recorded capture) need not
import the detection stage, which opens one.
"""

from __future__ import annotations

from collections.abc import Callable

Progress = Callable[[str], None]  # a stage's progress messages


def quiet(_: str) -> None:
    return None


def seam_counter(progress: Progress) -> Callable[[int, int], None]:
    """How the planner's count of seams searched reaches the user: ``progress.count(what, done, total)`` when
    the callable has one (a bar: the CLI draws it on a terminal), else a line ``planned k/n seams`` through
    ``progress`` at every tenth of the seams and at the end."""
    count = getattr(progress, "count", None)
    if callable(count):
        return lambda done, total: count("planning seams", done, total)
    shown = [-1]

    def line(done: int, total: int) -> None:
        tenth = 10 * done // max(total, 1)
        if tenth > shown[0] or done == total:
            shown[0] = tenth
            progress(f"planned {done}/{total} seams")

    return line
