"""What every command shares: the typer apps, the consoles, the global options, error handling, option parsing. Heavy
packages are imported inside the commands so ``cell --help`` is instant; progress goes to stderr, results to stdout;
every :class:`~cell.errors.CellError` becomes one line and its exit code, and nothing else is caught (a bug shows its
traceback)."""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal

import typer
from rich.console import Console
from rich.markup import escape

from cell.errors import CellError, OutputError, UsageError

if TYPE_CHECKING:
    from cell.scenario import Scenario

CONTEXT = {"help_option_names": ["-h", "--help"]}
app = typer.Typer(
    no_args_is_help=True,
    context_settings=CONTEXT,
    help="Robotic weld cell: find weld seams with depth cameras and a DXF welding map, in simulation.",
)
map_app = typer.Typer(no_args_is_help=True, context_settings=CONTEXT, help="Welding maps (DXF).")
app.add_typer(map_app, name="map")

# No fixed width: tables take the terminal's (rich falls back to 80 columns, or $COLUMNS, when not a terminal).
err = Console(stderr=True, highlight=False)
out = Console(highlight=False)
log = logging.getLogger("cell")
log.addHandler(logging.NullHandler())  # the console lines are printed here; only --log-file adds a handler

NoiseOpt = Annotated[str | None, typer.Option("--noise", help="Override the scenario's noise model: none | realistic.")]
CalibrationOpt = Annotated[
    Path | None,
    typer.Option(
        "--calibration",
        metavar="CAL.yaml",
        help="Camera poses measured by `cell calibrate`, applied over the scenario's (and their stated residual).",
    ),
]
FormatOpt = Annotated[str, typer.Option("--format", help="How the result table is printed: table | json | csv.")]
TableFormat = Literal["table", "json", "csv"]


@dataclass
class Settings:
    """The global options of this invocation (reset by every ``cell ...``); ``interrupted`` once Ctrl-C came."""

    quiet: bool = False
    verbose: bool = False
    interrupted: bool = False


def _on_sigint(signum: int, frame: object) -> None:
    settings.interrupted = True
    raise KeyboardInterrupt


def was_interrupted(e: BaseException) -> bool:
    """Ctrl-C, also when it arrived inside a C extension's import (which turns it into an ImportError)."""
    return isinstance(e, KeyboardInterrupt) or settings.interrupted


settings = Settings()
_handlers: list[logging.Handler] = []


class _MapWarnings(logging.Handler):
    """The welding map reader's warnings (a units doubt, a skipped body, a curve not welded) as ``warning:`` lines
    on stderr, whichever command read the map (unless --quiet)."""

    def emit(self, record: logging.LogRecord) -> None:
        if not settings.quiet:
            err.print(f"[yellow]warning[/]: {escape(record.getMessage())}", soft_wrap=True)


_map_warnings = _MapWarnings(logging.WARNING)
logging.getLogger("cell.weldmap").addHandler(_map_warnings)


def configure(*, quiet: bool, verbose: bool, log_file: Path | None) -> None:
    """Set this invocation's verbosity and log file; results go back to stdout (``--json -`` moves them)."""
    settings.quiet, settings.verbose, settings.interrupted = quiet, verbose, False
    with contextlib.suppress(ValueError):  # only the main thread may set a handler (it is the default's twin)
        signal.signal(signal.SIGINT, _on_sigint)
    out.stderr = False
    for h in _handlers:
        log.removeHandler(h)
        h.close()
    _handlers.clear()
    log.setLevel(logging.DEBUG)
    log.propagate = False
    if log_file is not None:
        from cell.outputs import check_file

        try:
            check_file(log_file, "--log-file", probe=False)  # appended to, never replaced: a FIFO would block
            handler = logging.FileHandler(log_file, encoding="utf-8")
        except OutputError as e:
            err.print(f"[bold red]error[/]: {escape(e.message)}", soft_wrap=True)
            raise typer.Exit(2) from None
        except OSError as e:
            err.print(f"[bold red]error[/]: cannot write the log file {str(log_file)!r}: {e.strerror or e}")
            raise typer.Exit(2) from None
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        log.addHandler(handler)
        _handlers.append(handler)


def results_to_stderr() -> None:
    """stdout carries a JSON document (``--json -``): tables and summaries go to stderr instead."""
    out.stderr = True


def say(msg: str) -> None:
    """A progress line: stderr (unless --quiet) and the log file. Never hard-wrapped."""
    log.info(msg)
    if not settings.quiet:
        err.print(f"[dim]· {escape(msg)}[/]", soft_wrap=True)


def detail(msg: str) -> None:
    """A detail line: stderr with --verbose only, the log file always."""
    log.debug(msg)
    if settings.verbose and not settings.quiet:
        err.print(f"[dim]  {msg}[/]", soft_wrap=True, markup=False)


def warn(msg: str) -> None:
    """A warning line: stderr (also with --quiet) and the log file."""
    log.warning(msg)
    err.print(f"[yellow]warning[/]: {escape(msg)}", soft_wrap=True, highlight=False)


def fail_line(msg: str) -> None:
    """The last line of a failed command: what went wrong (always shown, also with --quiet)."""
    log.error(msg)
    err.print(msg, soft_wrap=True, markup=False, highlight=False)


@contextmanager
def cell_errors() -> Iterator[None]:
    """Turn a CellError into its one-line message and exit code."""
    try:
        yield
    except CellError as e:
        log.error(e.message)
        err.print(f"[bold red]error[/]: {escape(e.message)}", soft_wrap=True)
        raise typer.Exit(e.exit_code) from None


def progress() -> Callable[[str], None]:
    return say


def load_scenario(name: str, calibration: Path | None = None) -> Scenario:
    """The scenario ``name`` (a shipped name or a YAML path), with ``--calibration``'s measured camera poses over
    its own when given."""
    from cell import scenario as sc

    scn = sc.load(name)
    if calibration is None:
        return scn
    from cell.calibrate.file import apply, flagged, read

    doc = read(calibration)
    for camera, what in flagged(doc).items():  # before any seam is located: the camera's model is in doubt
        warn(f"--calibration: camera {camera}'s calibration images disagree with its stated {', '.join(what)}")
    return apply(scn, doc, f"--calibration {str(calibration)!r}")


def parse_noise(value: str | None) -> Literal["none", "realistic"] | None:
    if value is None:
        return None
    if value not in ("none", "realistic"):
        raise typer.BadParameter(f"{value!r}; valid: none, realistic", param_hint="--noise")
    return "none" if value == "none" else "realistic"


def parse_rescan_mode(value: str | None) -> Literal["none", "low", "all"] | None:
    if value is None:
        return None
    if value not in ("none", "low", "all"):
        raise typer.BadParameter(f"{value!r}; valid: none, low, all", param_hint="--rescan")
    return "none" if value == "none" else ("low" if value == "low" else "all")


def parse_format(value: str) -> TableFormat:
    if value not in ("table", "json", "csv"):
        raise UsageError(f"--format {value!r}; valid: table, json, csv")
    return "table" if value == "table" else ("json" if value == "json" else "csv")


def check_method(method: str | None) -> None:
    from cell.seams.registry import METHODS

    if method is not None and method not in METHODS:
        raise typer.BadParameter(f"{method!r}; valid: {', '.join(METHODS)}", param_hint="--method")


def check_display(gui: bool) -> None:
    """``--gui`` needs a display: without one the simulator's window kills the process, so refuse first."""
    if gui and sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
        raise UsageError("--gui needs a display and $DISPLAY is not set; run without --gui (or under xvfb-run)")


def program_folder(program: Path | None, krl: Path | None) -> Path | None:
    """``--program DIR``; ``--krl DIR``, its old name, still works and says it is deprecated (not both)."""
    if krl is None:
        return program
    if program is not None:
        raise UsageError("--krl is the deprecated name of --program: give --program DIR alone")
    warn("--krl is deprecated: use --program DIR (KUKA KRL or ABB RAPID, as --controller says)")
    return krl
