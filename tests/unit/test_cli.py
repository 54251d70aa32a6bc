"""The command line: results on stdout, one-line errors with documented exit codes, the JSON report contract."""

from __future__ import annotations

from pathlib import Path

import pytest
from dxf_factory import design, make_maps
from typer.testing import CliRunner

from cell.cli import app
from cell.scenario import SCENARIO_DIR

runner = CliRunner()
REPO = Path(__file__).resolve().parents[2]


def invoke(*args: str) -> tuple[int, str, str]:
    result = runner.invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def assert_one_line_error(code: int, stderr: str, expected_code: int, *needles: str) -> None:
    assert code == expected_code, stderr
    lines = [ln for ln in stderr.strip().splitlines() if ln.startswith("error:")]
    assert len(lines) == 1, stderr
    assert "Traceback" not in stderr
    for n in needles:
        assert n in lines[0], lines[0]


def test_help_and_scenarios() -> None:
    code, out, _ = invoke("--help")
    assert code == 0 and "detect" in out
    code, out, _ = invoke("scenarios")
    assert code == 0
    for name in ("fence1-exact", "fence1", "fence2"):
        assert name in out


def test_map_info_lists_units_parts_and_seams() -> None:
    code, out, _ = invoke("map", "info", str(REPO / "maps" / "fence1.dxf"))
    assert code == 0
    assert "mm" in out
    for part in ("TOP_RAIL", "POST_L", "POST_R", "BOTTOM_RAIL"):
        assert part in out
    assert out.count("POST_L>TOP_RAIL:") == 4


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (b"\x00\x01\x02 not a drawing \xff" * 50, "DXF"),
        (b"hello, I am a text file\n", "DXF"),
    ],
)
def test_bad_dxf_gives_exit_11(tmp_path: Path, content: bytes, needle: str) -> None:
    bad = tmp_path / "bad.dxf"
    bad.write_bytes(content)
    code, _, err = invoke("map", "info", str(bad))
    assert_one_line_error(code, err, 11, needle)


def test_truncated_dxf_gives_exit_11(tmp_path: Path) -> None:
    good = (REPO / "maps" / "fence1.dxf").read_bytes()
    bad = tmp_path / "truncated.dxf"
    bad.write_bytes(good[: len(good) // 2])
    code, _, err = invoke("map", "info", str(bad))
    assert_one_line_error(code, err, 11, "truncated.dxf")


def test_unitless_dxf_gives_exit_12_and_names_the_fix(tmp_path: Path) -> None:
    parts, seams = design("fence1")
    path = make_maps.write_map(tmp_path / "nounits.dxf", parts, seams, units=None)
    code, _, err = invoke("map", "info", str(path))
    assert_one_line_error(code, err, 12, "map.units")
    code, out, _ = invoke("map", "info", str(path), "--units", "mm")
    assert code == 0 and "POST_L" in out


def test_scenario_with_a_typo_gives_exit_10(tmp_path: Path) -> None:
    text = (SCENARIO_DIR / "fence1.yaml").read_text().replace("seed:", "sede:")
    path = tmp_path / "typo.yaml"
    path.write_text(text.replace("../maps/", str(REPO / "maps") + "/"))
    code, _, err = invoke("detect", str(path))
    assert_one_line_error(code, err, 10, "sede", "seed")


def test_unknown_scenario_and_method(tmp_path: Path) -> None:
    code, _, err = invoke("detect", "fence99")
    assert_one_line_error(code, err, 10, "fence1")
    code, _, err = invoke("detect", "fence1", "--method", "magic")
    assert code == 2 and "paper" in err
