"""Commands that set a cell up: ``cell init`` (a scenario for one's own welding map) and ``cell scenario check``."""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from cell.cli.common import CONTEXT, app, cell_errors, out, say, warn

if TYPE_CHECKING:
    from cell.cli.sight_lines import SightReport
    from cell.scenario import Scenario
    from cell.types import WeldMap

scenario_app = typer.Typer(no_args_is_help=True, context_settings=CONTEXT, help="Scenario files (YAML).")
app.add_typer(scenario_app, name="scenario")

_warn = warn


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
    from cell.cli.sight_lines import arm_torch
    from cell.config.motion import ViewOptions
    from cell.outputs import make_folder, write_atomic
    from cell.rescan.sight import pose_sight
    from cell.scenario.init import ROBOT_URDF, scenario_text
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
        sight = partial(pose_sight, torch_C=arm_torch(ROBOT_URDF, ViewOptions()))  # the scan camera sees past it
        text, lay = scenario_text(map_file, target.absolute(), units=units, sight=sight)
        scn = sc.from_yaml(text, target.absolute().parent, target.name)  # what is written loads as it is
        make_folder(target.parent, "--out")  # the scenario's own folder (cells/ of cells/my_part.yaml), one level
        write_atomic(target, text.encode("utf-8"), what="scenario")
        size = lay.table_size
        say(
            f"wrote {target}: map {scn.map.file}, {len(scn.cameras)} cameras ({', '.join(lay.cameras)} and the "
            f"arm's), table {size[0]:.1f} x {size[1]:.1f} m, robot base at ({lay.X_WR_xyz[0]:.2f}, "
            f"{lay.X_WR_xyz[1]:.2f}) m"
        )
        if lay.unreachable_risk:
            _warn(f"a seam lies {lay.far_seam_m:.2f} m from the robot base: it may be unreachable")
        if lay.closeup_only:
            _warn(
                f"no fixed camera can see both faces of {', '.join(lay.closeup_only)} from around the part: only "
                "the close-up re-scan will"
            )
        say(f"next: cell scenario check {target}; cell preview {target}; cell weld {target}")


@scenario_app.command("check")
def check(
    file: Annotated[str, typer.Argument(help="A scenario YAML path (or a shipped scenario's name).")],
) -> None:
    """Validate a scenario as strictly as a run uses it: every key (typed, finite, in range, none given twice), the
    map it names, what the run checks before it moves (the robot's home within its joints' limits, the scan pose
    within the arm's reach, the part as built from the deviations), then the layout (the part on the table and
    inside the workspace, the cameras aimed at it and within range, the robot upright and facing it, the weld gate,
    each seam's two faces seen by a camera of the first scan: one line per seam). What the run would refuse is an
    error with the run's exit code; problems of the layout and seams no camera will see are warnings (exit 0)."""
    from cell import pipeline
    from cell import scenario as sc
    from cell.scenario.init import check_layout

    with cell_errors():
        scn = sc.load(file)
        weldmap = pipeline.read_weldmap(scn)
        problems = check_layout(scn, weldmap) + _run_checks(scn, weldmap)
        problems += [
            f"seam {u.id} will not be welded: not supported ({u.code}): {u.reason}" for u in weldmap.not_welded
        ]
        for p in problems:
            _warn(p)
        seams = _seam_sight(scn, weldmap)  # one line per seam, and a warning per seam no camera will see
        for w in seams.warnings:
            _warn(w)
        problems += seams.warnings
        fixed = sum(c.mount == "fixed" for c in scn.cameras.values())
        verdict = "ok" if not problems else f"{len(problems)} warning(s)"
        out.print(
            f"{verdict}: {file}: map {scn.map_path} ({len(weldmap.parts)} parts, {seams_text(weldmap)}), "
            f"{fixed} fixed camera(s), {len(scn.cameras) - fixed} on the arm",
            soft_wrap=True,
        )
        out.print(
            "seams as the first scan's cameras will see them (worst incidence on each face, range):", soft_wrap=True
        )
        for line in seams.lines:
            out.print(f"  {line}", soft_wrap=True, markup=False, highlight=False)


def _run_checks(scn: Scenario, weldmap: WeldMap) -> list[str]:
    """The run's own checks before anything moves (they raise as the run would: the arm's home and scan pose, the
    part as built), then
    the layout's warnings (:mod:`cell.scenario.layout_checks`)."""
    from cell.geometry import transform_points
    from cell.pipeline.geometry import robot_arm
    from cell.scenario import layout_checks as lc
    from cell.sim.asbuilt.parts import as_built_fixtures, as_built_parts
    from cell.sim.faults import built_parts

    arm = robot_arm(scn)  # home within the joints' limits, the scan pose within reach (IKError, exit 15)
    # The part as the simulated station builds it: the deviations, bows, gaps and missing parts name the map's parts
    built_parts(as_built_parts(weldmap, scn), scn.faults)
    as_built_fixtures(weldmap, scn)
    home_W = None
    if arm is not None:
        home_W = transform_points(scn.X_WR, arm.model.fk(arm.q_home)[None, :3, 3])[0]
    return [
        *lc.camera_problems(scn, weldmap),
        *lc.part_height_problems(scn, weldmap),
        *lc.robot_problems(scn, weldmap, home_W),
        *lc.gate_problems(scn),
        *lc.name_problems(scn, weldmap),
    ]


def _seam_sight(scn: Scenario, weldmap: WeldMap) -> SightReport:
    """``scenario check``'s seams as the cameras will see them (:mod:`cell.cli.sight_lines`)."""
    from cell.cli.sight_lines import sight_report

    return sight_report(scn, weldmap)


def seams_text(weldmap: WeldMap) -> str:
    """``3 seams: 2 to weld, 1 not supported (curved)``, or ``2 seams`` when the cell can weld every one."""
    n = len(weldmap.seams) + len(weldmap.not_straight)
    if not weldmap.not_welded:
        return f"{n} seams"
    codes = ", ".join(sorted({str(u.code) for u in weldmap.not_welded}))
    return f"{n} seams: {n - len(weldmap.not_welded)} to weld, {len(weldmap.not_welded)} not supported ({codes})"
