"""Commands that set a cell up: ``cell init`` (a scenario for one's own welding map) and ``cell scenario check``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cell.cli.common import CONTEXT, app, cell_errors, err, log, out, say

scenario_app = typer.Typer(no_args_is_help=True, context_settings=CONTEXT, help="Scenario files (YAML).")
app.add_typer(scenario_app, name="scenario")


def _warn(msg: str) -> None:
    """A warning line: stderr (also with --quiet) and the log file."""
    log.warning(msg)
    err.print(f"[yellow]warning[/]: {msg}", soft_wrap=True, highlight=False)


@app.command()
def init(
    map_file: Annotated[
        Path,
        typer.Argument(help="The welding map (DXF), or the part's CAD (STEP, STL, OBJ, PLY: made into a map first)."),
    ],
    out_path: Annotated[
        Path | None, typer.Option("--out", "-o", help="The scenario file to write (default: MAP's name .yaml here).")
    ] = None,
    units: Annotated[
        str | None,
        typer.Option(help="Units the DXF (or mesh) is drawn in (mm, cm, m, in); wins over its $INSUNITS."),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite the scenario file if it exists.")] = False,
) -> None:
    """Write a scenario for any welding map: table, robot and cameras placed around the part, the workspace
    computed, a comment on every key. Then `cell scenario check FILE` and `cell weld FILE`. Given a part's CAD,
    the map is made first beside the scenario, as `cell map from-cad` makes it (seams proposed from contacts)."""
    from cell import scenario as sc
    from cell.export.atomic import write_atomic
    from cell.scenario.init import scenario_text
    from cell.weldmap import METRES_PER_UNIT

    target = out_path if out_path is not None else Path(f"{map_file.stem}.yaml")
    if target.suffix not in (".yaml", ".yml"):
        raise typer.BadParameter(f"{str(target)!r} must end in .yaml or .yml", param_hint="--out")
    if target.exists() and not force:
        raise typer.BadParameter(f"{str(target)!r} exists (--force overwrites it)", param_hint="--out")
    if not map_file.is_file():
        raise typer.BadParameter(f"no file {str(map_file)!r}", param_hint="MAP_FILE")
    if units is not None and units not in METRES_PER_UNIT:
        raise typer.BadParameter(f"{units!r}; valid: {', '.join(METRES_PER_UNIT)}", param_hint="--units")
    with cell_errors():
        from cell.cad import is_cad

        if is_cad(map_file):  # the map made from the CAD beside the scenario, then laid out as any map
            from cell.cli.cad import convert

            dxf = target.with_suffix(".dxf")
            if dxf.exists() and not force:
                raise typer.BadParameter(f"{str(dxf)!r} exists (--force overwrites it)", param_hint="--out")
            convert(map_file, dxf, units=units)
            map_file, units = dxf, None
        text, lay = scenario_text(map_file, target.absolute(), units=units)
        scn = sc.from_yaml(text, target.absolute().parent, target.name)  # what is written loads as it is
        write_atomic(target, text.encode("utf-8"), what="scenario")
        size = lay.table_size
        say(
            f"wrote {target}: map {scn.map.file}, {len(scn.cameras)} cameras, table {size[0]:.1f} x "
            f"{size[1]:.1f} m, robot base at ({lay.X_WR_xyz[0]:.2f}, {lay.X_WR_xyz[1]:.2f}) m"
        )
        if lay.unreachable_risk:
            _warn(f"a seam lies {lay.far_seam_m:.2f} m from the robot base: it may be unreachable")
        say(f"next: cell scenario check {target}; cell weld {target}")


@scenario_app.command("check")
def check(
    file: Annotated[str, typer.Argument(help="A scenario YAML path (or a shipped scenario's name).")],
) -> None:
    """Validate a scenario: every key, the map it names (found and readable), and the layout (the part on the
    table and inside the workspace, its seams within the arm's reach). Exit 0 when it loads; problems of the
    layout are printed as warnings."""
    from cell import pipeline
    from cell import scenario as sc
    from cell.scenario.init import check_layout

    with cell_errors():
        scn = sc.load(file)
        weldmap = pipeline.read_weldmap(scn)
        problems = check_layout(scn, weldmap)
        for p in problems:
            _warn(p)
        fixed = sum(c.mount == "fixed" for c in scn.cameras.values())
        verdict = "ok" if not problems else f"{len(problems)} warning(s)"
        out.print(
            f"{verdict}: {file}: map {scn.map_path} ({len(weldmap.parts)} parts, {len(weldmap.seams)} seams), "
            f"{fixed} fixed camera(s), {len(scn.cameras) - fixed} on the arm",
            soft_wrap=True,
        )
