"""The ``cell`` command: a thin typer layer over :mod:`cell.pipeline`.

- :mod:`cell.cli.common`: the apps, consoles, global settings, error handling and option parsing every command
  shares; :mod:`cell.cli.root`: the global options and the entry point;
- :mod:`cell.cli.outputs`: output paths checked before the run, written whatever happens, Ctrl-C's partial report;
- :mod:`cell.cli.look`: ``scenarios``, ``map info``, ``detect``, ``bench``;
- :mod:`cell.cli.act`: ``weld``, ``preview``, ``rescan``;
- :mod:`cell.cli.locate`: ``locate`` (seams in a point cloud someone brings);
- :mod:`cell.cli.capture`: ``capture`` (a capture folder) and the replay of ``detect --capture``;
- :mod:`cell.cli.tables`: what they print.
"""

from __future__ import annotations

from cell.cli import act, krl, look, setup  # noqa: F401 - importing them registers their commands (weld first in --help)
from cell.cli import capture as _capture  # noqa: F401 - registers ``cell capture``
from cell.cli import locate as _locate  # noqa: F401 - registers ``cell locate`` (after detect)
from cell.cli.common import app
from cell.cli.root import main

__all__ = ["app", "main"]
