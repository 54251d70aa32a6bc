"""``cell map from-cad``: a STEP assembly or a mesh (STL, OBJ, PLY) made into a welding map to review, with the
seams proposed from the bodies' contacts and a picture of them (docs/maps.md, "Your own CAD part")."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from cell.cli.common import cell_errors, err, log, map_app, out, say
from cell.errors import UsageError

if TYPE_CHECKING:
    from cell.cad import Proposals

UNITS = ("mm", "cm", "m", "in")
GAP_MM, MIN_LENGTH_MM = 3.0, 20.0  # cell.cad.GAP_M and MIN_LENGTH_M (held equal by a test; cell.cad loads lazily)


def _warn(msg: str) -> None:
    log.warning(msg)
    err.print(f"[yellow]warning[/]: {msg}", soft_wrap=True, highlight=False, markup=False)


def convert(
    part: Path,
    target: Path,
    *,
    units: str | None,
    gap_mm: float = GAP_MM,
    min_length_mm: float = MIN_LENGTH_MM,
    picture: Path | None = None,
) -> Proposals:
    """Read ``part``, propose its seams, write the map to ``target`` and the picture beside it (or to
    ``picture``); print the proposals, one line each. Raises CellError (MapError, MapUnitsError, UsageError)."""
    from cell.cad import draw_proposals, propose, read_cad, summary_rows, write_proposals
    from cell.cli.outputs import check_file

    if units is not None and units not in UNITS:
        raise UsageError(f"--units {units!r}; valid: {', '.join(UNITS)}")
    if gap_mm < 0.0 or min_length_mm < 0.0:
        raise UsageError("--gap and --min-length are lengths in mm, zero or more")
    if target.suffix.lower() != ".dxf":
        raise UsageError(f"--out {str(target)!r}: the map is a DXF file (name it .dxf)")
    png = picture if picture is not None else target.with_suffix(".png")
    check_file(target, "--out", stdout_ok=False)
    check_file(png, "--picture", stdout_ok=False)
    model = read_cad(part, units=units)
    for w in model.warnings:
        _warn(w)
    say(f"read {part}: {len(model.bodies)} bodies, in {model.units}; proposing seams where they meet")
    found = propose(model, gap_m=gap_mm / 1000.0, min_length_m=min_length_mm / 1000.0)
    write_proposals(found, target)
    draw_proposals(found, png)
    counts = {r: sum(1 for x in found.roles if x == r) for r in set(found.roles)}
    bodies = ", ".join(f"{n} {r.value}{'s' if n > 1 else ''}" for r, n in sorted(counts.items()))
    rows = summary_rows(found)
    width = max([len(r[0]) for r in rows] + [4])
    out.print(f"{'seam':{width}s}  shape   length mm  joint   deg  status", soft_wrap=True, markup=False)
    for seam_id, shape, length, joint, deg, status in rows:
        out.print(
            f"{seam_id:{width}s}  {shape:6s}  {length:>9s}  {joint:6s}  {deg:>3s}  {status}",
            soft_wrap=True,
            markup=False,
        )
    curved = sum(1 for s in found.proposed if s.curved)
    out.print(
        f"{len(found.proposed)} seams proposed ({curved} curved), "
        f"{len(found.seams) - len(found.proposed)} rejected; bodies: {bodies}",
        soft_wrap=True,
        markup=False,
    )
    say(f"wrote {target} (proposals red on WELD_SEAMS, rejected on WELD_REJECTED) and {png}")
    return found


@map_app.command("from-cad")
def from_cad(
    part: Annotated[Path, typer.Argument(help="The part's CAD: STEP (.step, .stp) or a mesh (.stl, .obj, .ply).")],
    target: Annotated[Path, typer.Option("--out", "-o", help="The welding map to write (DXF).")],
    units: Annotated[
        str | None,
        typer.Option(
            help="Units of the file (mm, cm, m, in): a mesh needs them unless its size tells; a STEP declares its own."
        ),
    ] = None,
    gap_mm: Annotated[float, typer.Option("--gap", help="Bodies this close (mm) touch.")] = GAP_MM,
    min_length_mm: Annotated[
        float, typer.Option("--min-length", help="Fillets shorter than this (mm) are listed as rejected, not proposed.")
    ] = MIN_LENGTH_MM,
    picture: Annotated[
        Path | None, typer.Option(help="The picture of the proposals (PNG; default: the map's name, .png).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite the map if it exists.")] = False,
) -> None:
    """Make a welding map from a part's CAD: the bodies (parts; bolts, nuts and washers and bodies named like
    fixtures as fixtures) and the fillets where they meet, proposed red, with a picture of them. Review it (`cell
    map info MAP`, the picture, any CAD program: move a seam to layer WELD_REJECTED to drop it), then `cell init
    MAP`."""
    if target.exists() and not force:
        raise typer.BadParameter(f"{str(target)!r} exists (--force overwrites it)", param_hint="--out")
    with cell_errors():
        convert(part, target, units=units, gap_mm=gap_mm, min_length_mm=min_length_mm, picture=picture)
        say(f"next: cell map info {target}; cell init {target}")
