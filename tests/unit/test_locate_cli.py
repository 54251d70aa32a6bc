"""``cell locate``: bad input refused before any work (one line, its exit code, no traceback), and one run on a
synthetic scan of fence1 (its parts' faces and the table sampled at a known pose, 0.3 mm noise)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cloud_writers import map_cloud, pcd_ascii, ply_binary
from typer.testing import CliRunner

from cell.cli import app
from cell.geometry import pose_from_xyz_rpy, transform_points
from cell.perception.cloud_files import read_cloud
from cell.weldmap import read_map

runner = CliRunner()
REPO = Path(__file__).resolve().parents[2]
FENCE1 = REPO / "maps" / "fence1.dxf"
X_FM = pose_from_xyz_rpy(np.array([0.2, -0.5, 0.01]), [0.0, 0.0, math.radians(15.0)])  # the true pose
PLACE = "208,-495,10,15.8"  # the nominal one: 9 mm and 0.8 deg off


def invoke(*args: str) -> tuple[int, str, str]:
    result = runner.invoke(app, list(args))
    return result.exit_code, result.stdout, result.stderr


def assert_one_line_error(code: int, stderr: str, expected: int, *needles: str) -> None:
    assert code == expected, stderr
    lines = [ln for ln in stderr.strip().splitlines() if ln.startswith("error:")]
    assert len(lines) == 1, stderr
    assert "Traceback" not in stderr
    for n in needles:
        assert n in lines[0], lines[0]


@pytest.fixture(scope="module")
def scan(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict[str, np.ndarray]]:
    """fence1 scanned at X_FM (binary PLY, metres), its truth file (mm, frame F) and the true ends (2, 3) [m]."""
    folder = tmp_path_factory.mktemp("scan")
    weldmap = read_map(FENCE1)
    p_F = map_cloud(weldmap, X_FM, np.random.default_rng(3), pitch_m=0.006, noise_m=3e-4)
    ends = {s.id: transform_points(X_FM, np.vstack([s.p_start, s.p_end])) for s in weldmap.seams}
    truth = {"units": "mm", "frame": "F", "seams": {k: {"start": list(v[0] * 1e3), "end": list(v[1] * 1e3)}
                                                    for k, v in ends.items()}}  # fmt: skip
    (folder / "truth.json").write_text(json.dumps(truth))
    return ply_binary(folder / "fence1.ply", p_F), folder / "truth.json", ends


@pytest.fixture
def tiny(tmp_path: Path) -> Path:
    """A small valid cloud: enough to pass every check made before the work."""
    return pcd_ascii(tmp_path / "tiny.pcd", np.random.default_rng(0).random((50, 3)) * 0.3)


def _offset_mm(found: dict, ends_F: np.ndarray) -> float:
    """The largest distance [mm] of the found ends from the true segment's ends (either direction)."""
    d = np.array([found["start"], found["end"]])
    return 1e3 * min(np.abs(d - ends_F).max(), np.abs(d[::-1] - ends_F).max())


def test_locate_finds_fence1_in_a_synthetic_scan(scan: tuple[Path, Path, dict], tmp_path: Path) -> None:
    cloud, _, ends = scan
    report, saved = tmp_path / "r.json", tmp_path / "used.ply"
    code, out, err = invoke(
        "locate", str(cloud), "--map", str(FENCE1), "--place", PLACE, "--json", str(report), "--save-cloud",
        str(saved), "--format", "csv",
    )  # fmt: skip
    assert code == 0, err
    rep = json.loads(report.read_text())
    assert rep["frame"] == "F" and rep["units"] == "m" and rep["error"] is None
    assert rep["provenance"]["cloud_sha256"] and rep["provenance"]["map_file"] == str(FENCE1)
    found = [s for s in rep["seams"] if s["status"] == "found"]
    assert len(found) == 12 and {s["status"] for s in rep["seams"]} == {"found", "not_visible"}  # -z: on the table
    for s in rep["seams"]:
        assert "truth" not in s and "error_mm" not in s
    offsets = {s["id"]: _offset_mm(s["detected"], ends[s["id"]]) for s in found}
    assert max(offsets.values()) < 0.3, offsets  # measured: 0.015-0.058 mm (6 mm pitch, 0.3 mm noise)
    assert rep["summary"]["found"] == 12 and rep["summary"]["paper_me_mean_mm"] is None
    assert out.startswith("seam,status,") and len(out.strip().splitlines()) == 17
    used = read_cloud(saved, frame="F")  # the cloud as given to the pipeline: every point of the file, in metres
    assert len(used) == len(read_cloud(cloud)) and np.allclose(used.points, read_cloud(cloud).points)


def test_locate_with_truth_reports_errors(scan: tuple[Path, Path, dict]) -> None:
    cloud, truth, _ = scan
    code, out, err = invoke("locate", str(cloud), "--map", str(FENCE1), "--place", PLACE, "--truth", str(truth),
                            "--json", "-")  # fmt: skip
    assert code == 0, err
    rep = json.loads(out)
    found = [s for s in rep["seams"] if s["status"] == "found"]
    assert len(found) == 12
    for s in found:
        assert s["truth"] and s["error_mm"]["lateral"] < 0.3
    assert rep["summary"]["lateral_mean_mm"] < 0.15  # measured 0.03
    assert "located seams · frame F" in err  # the tables went to stderr: stdout is the JSON


@pytest.mark.parametrize(
    ("extra", "needles"),
    [
        (["--place", "1,2,3"], ["--place", "4 values"]),
        (["--place", "1,2,3,x"], ["--place", "not numbers"]),
        (["--place", "1,2,3,4", "--place-rpy", "1,2,3,4,5,6"], ["both given"]),
        (["--units", "feet"], ["--units 'feet'", "valid: m, cm, mm, in"]),
        (["--map-units", "furlong"], ["--map-units"]),
        (["--frame", "base link"], ["--frame"]),
        (["--viewpoint", "1,2"], ["--viewpoint"]),
        (["--format", "xml"], ["--format"]),
        (["--table-z", "-5", "--no-table"], ["--table-z and --no-table", "one of them"]),
        (["--table-z", "nan"], ["--table-z", "finite"]),
    ],
)
def test_bad_options_exit_2_before_any_work(tiny: Path, extra: list[str], needles: list[str]) -> None:
    code, _, err = invoke("locate", str(tiny), "--map", str(FENCE1), *extra)
    assert_one_line_error(code, err, 2, *needles)


def test_bad_method_and_missing_map_exit_2(tiny: Path, tmp_path: Path) -> None:
    code, _, err = invoke("locate", str(tiny), "--map", str(FENCE1), "--method", "magic")
    assert code == 2 and "magic" in err and "Traceback" not in err
    code, _, err = invoke("locate", str(tiny), "--map", str(tmp_path / "none.dxf"))
    assert_one_line_error(code, err, 2, "--map", "does not exist")
    code, _, err = invoke("locate", str(tiny))
    assert code == 2 and "--map" in err


@pytest.mark.parametrize(
    ("content", "needles"),
    [
        (None, ["does not exist"]),
        (b"", ["is empty"]),
        (b"solid cube\nfacet normal 0 0 1\n", ["neither PLY nor PCD"]),
        (b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
         b"end_header\nnan nan nan\n", ["NaN or infinite"]),
    ],
)  # fmt: skip
def test_unusable_clouds_exit_2(tmp_path: Path, content: bytes | None, needles: list[str]) -> None:
    path = tmp_path / "scan.ply"
    if content is not None:
        path.write_bytes(content)
    code, _, err = invoke("locate", str(path), "--map", str(FENCE1))
    assert_one_line_error(code, err, 2, str(path), *needles)


def test_millimetres_by_mistake_name_the_fix(tmp_path: Path) -> None:
    p = np.random.default_rng(1).random((100, 3)) * [260.35, 50.8, 50.8] + [0.0, -609.6, 0.0]  # a tee in mm
    path = ply_binary(tmp_path / "mm.ply", p)
    code, _, err = invoke("locate", str(path), "--map", str(FENCE1), "--place", "0,-609.6,25.4,0")
    assert_one_line_error(code, err, 2, "looks like millimetres: pass --units mm")


def test_bad_truth_files_exit_2(tmp_path: Path) -> None:
    p = np.random.default_rng(0).random((50, 3)) * 0.3
    p[[4, 9], 0] = np.nan  # dropped, with a warning, before the truth file is read
    tiny = pcd_ascii(tmp_path / "tiny.pcd", p)
    truth = tmp_path / "truth.json"
    for content, needle in (
        ("{not json", "not readable JSON"),
        ('{"seams": {"NOPE": {"start": [0, 0, 0], "end": [1, 0, 0]}}}', "seams not in the map: NOPE"),
        ('{"units": "m", "seams": {}}', "units 'm'"),
        ('{"frame": "R", "seams": {}}', "frame 'R'"),
        ('{"seams": {}}', "no truth for POST_L>TOP_RAIL:+x"),
    ):
        truth.write_text(content)
        code, _, err = invoke("locate", str(tiny), "--map", str(FENCE1), "--truth", str(truth))
        assert_one_line_error(code, err, 2, "--truth", needle)
        assert "warning: point cloud" in err and "dropped 2 of 50 points" in err


def test_an_unwritable_output_exits_2_before_reading(tiny: Path, tmp_path: Path) -> None:
    code, _, err = invoke("locate", str(tiny), "--map", str(FENCE1), "--json", str(tmp_path))
    assert_one_line_error(code, err, 2, "--json", "is a folder")
    code, _, err = invoke("locate", str(tiny), "--map", str(FENCE1), "--save-cloud", "-")
    assert_one_line_error(code, err, 2, "--save-cloud")


def test_ctrl_c_writes_the_interrupted_report(tiny: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import cell.pipeline.cloud

    def interrupted(*args: object, **kwargs: object) -> None:
        kwargs["progress"]("finding the table plane")  # type: ignore[operator]
        raise KeyboardInterrupt

    monkeypatch.setattr(cell.pipeline.cloud, "locate_cloud", interrupted)
    report = tmp_path / "r.json"
    code, _, err = invoke("locate", str(tiny), "--map", str(FENCE1), "--frame", "R", "--json", str(report))
    assert code == 130 and "Traceback" not in err
    assert err.strip().splitlines()[-1].startswith("exit 130: interrupted (Ctrl-C) during: finding the table plane")
    rep = json.loads(report.read_text())
    assert rep["interrupted"] == {"stage": "finding the table plane"} and rep["frame"] == "R" and rep["seams"] == []
    assert rep["error"]["exit_code"] == 130 and rep["provenance"]["cloud_file"] == str(tiny)


def test_no_table_and_a_stated_table_height_are_said_and_run(tmp_path: Path) -> None:
    """The flat tee scanned all round and cropped 5 mm above its table, as a PCD: recognised as having no table, or
    told so, or told the table's height; each run aligns it on its own faces and finds both fillets."""
    flat = REPO / "maps" / "tee_flat.dxf"
    X = pose_from_xyz_rpy(np.array([-0.05, -0.02, 0.0]), [0.0, 0.0, math.radians(8.0)])
    P = map_cloud(read_map(flat), X, np.random.default_rng(4), pitch_m=0.0025, noise_m=0.001)
    cloud = pcd_ascii(tmp_path / "cropped.pcd", P[P[:, 2] >= 0.005])
    for extra, line in (([], "no table in the cloud"), (["--no-table"], "no table"), (["--table-z", "0"], "given")):
        code, out, err = invoke("locate", str(cloud), "--map", str(flat), *extra)
        assert code == 0, err
        assert line in err and "found 2/2 visible" in out, (out, err)
