"""The ``cell`` command: a thin typer layer over :mod:`cell.pipeline`, one module per group of commands
(docs/cli.md; the modules: docs/architecture.md section 2)."""

from __future__ import annotations

from cell.cli import act, krl, look, setup  # noqa: F401 - importing them registers their commands (weld first in --help)
from cell.cli import cad as _cad  # noqa: F401 - registers ``cell map from-cad``
from cell.cli import capture as _capture  # noqa: F401 - registers ``cell capture``
from cell.cli import locate as _locate  # noqa: F401 - registers ``cell locate`` (after detect)
from cell.cli.common import app
from cell.cli.root import main

__all__ = ["app", "main"]
