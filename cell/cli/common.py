"""What every command shares: the typer apps, the consoles, the error handler, option parsing.

Heavy packages (pybullet, open3d, pinocchio) are imported inside the commands so ``cell --help`` is instant.
Progress goes to stderr, results to stdout. Every :class:`~cell.errors.CellError` becomes a one-line message and its
documented exit code (see :mod:`cell.errors`); nothing else is caught, so a bug still shows its traceback.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Annotated, Literal

import typer
from rich.console import Console

from cell.errors import CellError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Robotic weld cell: find weld seams with depth cameras and a DXF welding map, in simulation.",
)
map_app = typer.Typer(no_args_is_help=True, help="Welding maps (DXF).")
app.add_typer(map_app, name="map")

err = Console(stderr=True, highlight=False)
out = Console(highlight=False, width=140)

NoiseOpt = Annotated[str | None, typer.Option("--noise", help="Override the scenario's noise model: none | realistic.")]


@contextmanager
def cell_errors() -> Iterator[None]:
    """Turn a CellError into its one-line message and exit code."""
    try:
        yield
    except CellError as e:
        err.print(f"[bold red]error[/]: {e.message}", soft_wrap=True)
        raise typer.Exit(e.exit_code) from None


def progress() -> Callable[[str], None]:
    def say(msg: str) -> None:
        err.print(f"[dim]· {msg}[/]")

    return say


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


def check_method(method: str | None) -> None:
    from cell.seams.registry import METHODS

    if method is not None and method not in METHODS:
        raise typer.BadParameter(f"{method!r}; valid: {', '.join(METHODS)}", param_hint="--method")
