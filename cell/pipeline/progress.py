"""How a stage reports progress: a callable taking one message (the CLI prints them on stderr), quiet by default.

Its own module so that paths which never build a simulated cell (``cell locate``, a recorded capture) need not
import the detection stage, which opens one.
"""

from __future__ import annotations

from collections.abc import Callable

Progress = Callable[[str], None]  # a stage's progress messages


def quiet(_: str) -> None:
    return None
