"""``cell map info`` as a user meets it: warnings on stderr, joints per seam, fixtures and unsupported seams listed,
units overridden, a scenario's layers, and one-line errors that say what to type."""

from __future__ import annotations

from pathlib import Path

from dxf_factory import REPO_ROOT, design, make_maps, scaled
from typer.testing import CliRunner

from cell.cli import app

PARTS, SEAMS = design("fence1")


def invoke(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def test_map_info_lists_joints_fixtures_and_unsupported_seams(tmp_path: Path) -> None:
    doc = make_maps.build_map(PARTS, SEAMS, solid="mesh")
    msp = doc.modelspace()
    make_maps.box_mesh((500, 560, 0), (560, 620, 120)).render_mesh(msp, dxfattribs={"layer": "CLAMP_1"})
    msp.add_arc((240, 700, 0), 40, 0, 180, dxfattribs={"color": 1})
    doc.saveas(tmp_path / "v.dxf")
    code, out, err = invoke("map", "info", str(tmp_path / "v.dxf"))
    assert code == 0, err
    assert "TOP_RAIL     box (MESH)" in out and "fixtures: 1" in out and "CLAMP_1" in out
    assert "POST_L>TOP_RAIL:+z" in out and "T 90 deg  POST_L > TOP_RAIL" in out
    assert "unsupported seams" not in out and "curved seams: 1 (a run locates each and welds it or says why not" in out
    assert "arc r 40.0 mm" in out and "[ARC " in out


def test_map_info_warns_on_stderr_and_takes_the_users_units(tmp_path: Path) -> None:
    path = make_maps.write_map(tmp_path / "v.dxf", *scaled(PARTS, SEAMS, 1e-3), units=1, solid="mesh")  # m as in
    code, out, err = invoke("map", "info", str(path))
    assert code == 0 and "units: in" in out
    assert err.startswith("warning: ") and f"`cell map info {path} --units m`" in " ".join(err.split())
    code, out, err = invoke("map", "info", str(path), "--units", "m")
    assert code == 0 and "1400.0 x 100.0 x 100.0 mm" in out
    assert "declares $INSUNITS=1 (in); read in m as asked" in " ".join(err.split())


def test_map_info_reads_a_scenarios_layers() -> None:
    code, out, err = invoke("map", "info", str(REPO_ROOT / "maps" / "fence1.dxf"), "--scenario", "fence1")
    assert code == 0 and err == "" and "seams: 16" in out


def test_map_info_on_a_2d_drawing_says_what_it_found(tmp_path: Path) -> None:
    import ezdxf

    doc = ezdxf.new("R2010", units=0)
    for i in range(30):
        doc.modelspace().add_line((i, 0), (i, 10))
    doc.saveas(tmp_path / "plan.dxf")
    code, _, err = invoke("map", "info", str(tmp_path / "plan.dxf"))
    text = " ".join(err.split())
    assert code == 11 and text.startswith("error: ") and "not a welding map: 30 LINEs, none red; no 3D bodies" in text
    assert "Traceback" not in err and "units" not in text.split("not a welding map")[0]
