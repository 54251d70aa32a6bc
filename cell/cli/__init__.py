"""The ``cell`` command: a thin typer layer over :mod:`cell.pipeline`.

- :mod:`cell.cli.common`: the apps, consoles, error handling and option parsing every command shares;
- :mod:`cell.cli.look`: ``scenarios``, ``map info``, ``detect``, ``bench``;
- :mod:`cell.cli.act`: ``weld``, ``preview``, ``rescan``;
- :mod:`cell.cli.tables`: what they print.
"""

from __future__ import annotations

import sys

from cell.cli import act, look, setup  # noqa: F401 - importing them registers their commands (weld first in --help)
from cell.cli.common import app

__all__ = ["app", "main"]


def main() -> None:
    """Console-script entry point."""
    try:
        app()
    except KeyboardInterrupt:
        sys.exit(130)
