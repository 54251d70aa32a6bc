"""``cell init`` and ``cell scenario check``: a scenario written for any welding map, map files found for a scenario
copied elsewhere, the layout checked."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml
from dxf_factory import design, make_maps, scaled
from typer.testing import CliRunner

from cell import scenario as sc
from cell.cli import app
from cell.errors import ScenarioError
from cell.scenario.init import check_layout, layout, map_reference, scenario_text
from cell.weldmap import read_map

REPO = Path(__file__).resolve().parents[2]
FENCE2 = REPO / "maps" / "fence2.dxf"
runner = CliRunner()


def test_the_layout_for_fence2_is_the_shipped_fence2_cell(tmp_path: Path) -> None:
    """The rules are the shipped layout's, relative to the part: on fence2 they give fence2.yaml's cell."""
    text, lay = scenario_text(FENCE2, tmp_path / "f2.yaml")
    written, shipped = sc.from_yaml(text, tmp_path, "f2.yaml"), sc.load("fence2")
    assert written.map_path == shipped.map_path
    assert written.map.X_WM == shipped.map.X_WM
    assert written.table == shipped.table and written.robot == shipped.robot
    assert written.cameras == shipped.cameras
    assert written.perception.workspace == shipped.perception.workspace
    # What only a simulation knows is left at a healthy, exactly built cell.
    assert written.deviations == {} and written.simulation.placement_error == sc.PoseSpec()
    assert written.faults == sc.FaultsSpec() and written.noise == "realistic"
    assert check_layout(written, read_map(FENCE2)) == [] and not lay.unreachable_risk


def test_every_key_has_a_comment(tmp_path: Path) -> None:
    text, _ = scenario_text(FENCE2, tmp_path / "f2.yaml")
    keys = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    assert len(keys) >= 30
    for ln in keys:
        assert "  # " in ln and ln.split("  # ", 1)[1].strip(), ln
    assert isinstance(yaml.safe_load(text), dict)


def test_a_long_part_gets_a_pair_of_fixed_cameras_per_section() -> None:
    lay = layout(read_map(REPO / "maps" / "ladder.dxf"))  # 2.0 m long: two sections of 1.0 m
    assert sorted(lay.cameras) == ["cam_left_1", "cam_left_2", "cam_right_1", "cam_right_2"]
    targets_x = sorted({round(float(t[0]), 6) for _, t in lay.cameras.values()})
    assert targets_x == pytest.approx([-0.35, 0.65])
    lo, hi = lay.workspace
    assert np.all(lo[:2] <= lay.lo_W[:2] - 0.15) and np.all(hi[:2] >= lay.hi_W[:2] + 0.15)
    assert lay.table_size[0] == pytest.approx(2.4)  # the 2.0 m part + 0.2 m a side
    assert lay.unreachable_risk and lay.far_seam_m == pytest.approx(1.64, abs=0.01)


def test_the_map_reference_resolves_from_where_the_scenario_is_written(tmp_path: Path) -> None:
    assert map_reference(FENCE2, tmp_path) == "fence2.dxf"  # found by name in maps/
    (tmp_path / "maps").mkdir()
    own = tmp_path / "maps" / "mine.dxf"
    shutil.copy(FENCE2, own)
    assert map_reference(own, tmp_path) == "maps/mine.dxf"
    assert map_reference(own, tmp_path / "elsewhere") == str(own.resolve())


def test_a_copied_scenario_finds_its_map_beside_it_then_in_maps(tmp_path: Path) -> None:
    (tmp_path / "scn").mkdir()
    copy = tmp_path / "scn" / "fence1.yaml"
    shutil.copy(sc.SCENARIO_DIR / "fence1.yaml", copy)  # says ../maps/fence1.dxf: not beside the copy
    assert sc.load(copy).map_path == REPO / "maps" / "fence1.dxf"
    (tmp_path / "maps").mkdir()
    beside = tmp_path / "maps" / "fence1.dxf"
    shutil.copy(REPO / "maps" / "fence1.dxf", beside)
    assert sc.load(copy).map_path == beside.resolve()  # relative to the scenario first
    text = copy.read_text().replace("fence1.dxf", "nope.dxf")
    with pytest.raises(ScenarioError) as exc:
        sc.from_yaml(text, copy.parent, "copy.yaml")
    assert "map.file '../maps/nope.dxf' does not exist" in str(exc.value)
    assert str(REPO / "maps" / "nope.dxf") in str(exc.value)  # both places it looked


def test_cell_init_writes_a_scenario_that_checks(tmp_path: Path) -> None:
    out = tmp_path / "sub" / "f2.yaml"
    result = runner.invoke(app, ["init", str(FENCE2), "--out", str(out)])
    assert result.exit_code == 0, result.stderr
    assert sc.load(out).name == "f2"
    result = runner.invoke(app, ["scenario", "check", str(out)])
    assert result.exit_code == 0, result.stderr
    assert result.stdout.startswith("ok:") and "16 seams" in result.stdout
    again = runner.invoke(app, ["init", str(FENCE2), "--out", str(out)])
    assert again.exit_code == 2 and "--force" in again.stderr  # never overwrites unasked
    assert runner.invoke(app, ["init", str(FENCE2), "--out", str(out), "--force"]).exit_code == 0
    assert runner.invoke(app, ["init", str(tmp_path / "none.dxf"), "--out", str(tmp_path / "n.yaml")]).exit_code == 2
    bad_units = runner.invoke(app, ["init", str(FENCE2), "--out", str(tmp_path / "u.yaml"), "--units", "ft"])
    assert bad_units.exit_code == 2 and not (tmp_path / "u.yaml").exists()


def test_cell_scenario_check_reports_problems(tmp_path: Path) -> None:
    text, _ = scenario_text(FENCE2, tmp_path / "f2.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("max_m: [1.1, 0.55, 1.2]", "max_m: [0.5, 0.55, 1.2]"))
    result = runner.invoke(app, ["scenario", "check", str(bad)])
    assert result.exit_code == 0 and "1 warning" in result.stdout
    assert "not inside perception.workspace" in result.stderr
    typo = tmp_path / "typo.yaml"
    typo.write_text(text.replace("seed: 1", "sede: 1"))
    result = runner.invoke(app, ["scenario", "check", str(typo)])
    assert result.exit_code == 10 and "did you mean 'seed'" in result.stderr


def test_a_map_without_units_drawn_off_its_origin(tmp_path: Path) -> None:
    """A drawing in cm with no $INSUNITS, its parts far from its origin: --units is needed and kept in the file;
    the part still lands centred at (0.15, 0.0) on the table top."""
    parts, seams = design("fence2")
    parts, seams = scaled(parts, seams, 0.1)  # mm -> cm
    shift = np.array([50.0, -30.0, 10.0])  # [cm]

    def moved(p: tuple[float, float, float]) -> tuple[float, float, float]:
        x, y, z = np.asarray(p) + shift
        return (float(x), float(y), float(z))

    parts = {n: (moved(lo), moved(hi)) for n, (lo, hi) in parts.items()}
    seams = [(i, moved(p), moved(q)) for i, p, q in seams]
    dxf = make_maps.write_map(tmp_path / "mine.dxf", parts, seams, units=None)
    out = tmp_path / "mine.yaml"
    result = runner.invoke(app, ["init", str(dxf), "--out", str(out)])
    assert result.exit_code == 12, result.stderr  # no known units
    assert not out.exists()
    result = runner.invoke(app, ["init", str(dxf), "--out", str(out), "--units", "cm"])
    assert result.exit_code == 0, result.stderr
    s = sc.load(out)
    assert s.map.file == "mine.dxf" and s.map.units == "cm"
    assert s.map.X_WM.xyz_m == pytest.approx((-0.65 - 0.5, -0.36 + 0.3, 0.9 - 0.1))
    assert check_layout(s, read_map(s.map_path, units="cm")) == []
