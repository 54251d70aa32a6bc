"""The ``cell`` command itself: its global options (``--version``, ``-q``, ``-v``, ``--log-file``) and the
entry point that turns every failure into a last line of stderr saying why, and its exit code."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated

import typer

from cell.cli import calibrate as _calibrate  # noqa: F401 - registers ``cell calibrate`` (the cameras' poses)
from cell.cli import sweep as _sweep  # noqa: F401 - registers ``cell sweep`` (a tolerance study on Ray)
from cell.cli.common import app, configure, err, fail_line
from cell.cli.outputs import begin_command
from cell.errors import EXIT_INTERRUPTED, EXIT_USAGE


def _version(value: bool) -> None:
    if value:
        from cell.provenance import version_text

        typer.echo(version_text())
        raise typer.Exit()


@app.callback()
def root(
    ctx: typer.Context,
    version: Annotated[
        bool,
        typer.Option("--version", callback=_version, is_eager=True, help="Print the version (and git commit)."),
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress lines: results and errors only.")] = False,
    verbose: Annotated[bool, typer.Option("--verbose", "-v", help="More detail: the files read and written.")] = False,
    log_file: Annotated[
        Path | None, typer.Option("--log-file", help="Also write the progress, with times, to this file.")
    ] = None,
) -> None:
    """Robotic weld cell: find weld seams with depth cameras and a DXF welding map, in simulation."""
    configure(quiet=quiet, verbose=verbose, log_file=log_file)
    ctx.call_on_close(begin_command())  # the output folders this command holds, freed when it ends


def main() -> None:
    """Console-script entry point: a usage error is one ``error:`` line (exit 2), Ctrl-C exits 130."""
    try:
        code = app(standalone_mode=False)
    except typer.Abort:
        fail_line(f"exit {EXIT_INTERRUPTED}: interrupted")
        sys.exit(EXIT_INTERRUPTED)
    except typer.TyperException as e:  # typer's click: a usage error (no such option, bad value) or another
        ctx = getattr(e, "ctx", None)
        if ctx is not None:
            err.print(f"Try '{ctx.command_path} -h' for help.", markup=False, highlight=False)
        fail_line(f"error: {e.format_message() if hasattr(e, 'format_message') else e}")
        sys.exit(int(getattr(e, "exit_code", EXIT_USAGE)))
    except KeyboardInterrupt:
        fail_line(f"exit {EXIT_INTERRUPTED}: interrupted")
        sys.exit(EXIT_INTERRUPTED)
    sys.exit(code if isinstance(code, int) else 0)
