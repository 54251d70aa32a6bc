"""The post-processors by controller name: ``krl`` (KUKA, :mod:`cell.export.krl`) and ``rapid`` (ABB,
:mod:`cell.export.rapid`), each a :class:`~cell.export.program.PostProcessor`. ``cell weld --controller NAME``
picks one; a new controller is one module with a ``texts(job)`` and one line here."""

from __future__ import annotations

from pathlib import Path

from cell.export.krl import KrlPost
from cell.export.program import PostProcessor, ProgramJob, write_texts
from cell.export.rapid import RapidPost

POSTS: dict[str, PostProcessor] = {"krl": KrlPost(), "rapid": RapidPost()}


def post_processor(name: str) -> PostProcessor:
    """The post-processor called ``name``; ValueError naming the valid ones."""
    try:
        return POSTS[name]
    except KeyError:
        raise ValueError(f"controller {name!r} is unknown; valid: {', '.join(POSTS)}") from None


def write_program(controller: str, job: ProgramJob, directory: str | Path) -> list[Path]:
    """Write the job's program for ``controller`` into ``directory`` (CRLF line ends, each file atomically); the
    paths. ValueError for an unknown controller, OutputError when a file cannot be written."""
    return write_texts(post_processor(controller).texts(job), directory)
