"""Brought point cloud files (``read_cloud``): PLY and PCD in every layout the tests can write, and the bad files
each refused with its code (never a traceback, never a point that was not in the file)."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from cloud_writers import (
    box_surface,
    pcd_ascii,
    pcd_binary,
    pcd_binary_compressed,
    ply_ascii,
    ply_binary,
)

from cell.errors import CloudFault, CloudFileError, UsageError
from cell.perception.cloud_files import CloudFileWarning, read_cloud

REAL_SCANS = Path(__file__).resolve().parents[2].parent / "shared" / "real-scans"
TEE_SIZE_M = (0.26035, 0.0508, 0.0508)  # [m] the horizontal tube of the real scans' tee


@pytest.fixture
def points() -> np.ndarray:
    return box_surface(np.random.default_rng(7), 400, TEE_SIZE_M) + np.array([0.1, -0.6, 0.025])


WRITERS: dict[str, Callable[[Path, np.ndarray], Path]] = {
    "ply-ascii": ply_ascii,
    "ply-ascii-crlf": lambda p, x: ply_ascii(p, x, newline="\r\n"),
    "ply-binary-le": ply_binary,
    "ply-binary-be": lambda p, x: ply_binary(p, x, big_endian=True),
    "pcd-ascii-crlf": pcd_ascii,
    "pcd-ascii-lf": lambda p, x: pcd_ascii(p, x, newline="\n"),
    "pcd-binary": pcd_binary,
    "pcd-binary-compressed": pcd_binary_compressed,
}


@pytest.mark.parametrize("layout", list(WRITERS))
def test_every_layout_reads_the_points_written(tmp_path: Path, points: np.ndarray, layout: str) -> None:
    # Named .dat: the format is known by content, not by the name.
    path = WRITERS[layout](tmp_path / "cloud.dat", points)
    cloud = read_cloud(path, frame="B")
    assert cloud.frame == "B" and len(cloud) == len(points)
    tol = 1e-8 if "binary-" in layout and "ply" in layout else 1e-7  # float32 fields: rounding of 0.6 m values
    assert np.max(np.abs(cloud.points - points)) < tol
    assert np.all(cloud.camera == -1)


def test_millimetres_are_scaled_and_refused_as_metres(tmp_path: Path, points: np.ndarray) -> None:
    path = pcd_ascii(tmp_path / "mm.pcd", points * 1000.0)  # a 260 mm part written in millimetres
    with pytest.raises(CloudFileError) as e:
        read_cloud(path)
    assert e.value.code is CloudFault.UNITS and "--units mm" in e.value.message
    assert "\n" not in e.value.message
    cloud = read_cloud(path, units="mm")
    assert np.max(np.abs(cloud.points - points)) < 1e-6


def test_metres_read_as_millimetres_are_refused(tmp_path: Path, points: np.ndarray) -> None:
    path = ply_binary(tmp_path / "m.ply", points - points.mean(axis=0))  # spans 0.26 "mm" if read as mm
    with pytest.raises(CloudFileError) as e:
        read_cloud(path, units="mm")
    assert e.value.code is CloudFault.UNITS and "drop --units" in e.value.message


def test_nan_rows_are_dropped_with_a_warning(tmp_path: Path, points: np.ndarray) -> None:
    bad = points.copy()
    bad[[3, 10, 11], 1] = np.nan
    bad[20, 2] = np.inf
    path = pcd_ascii(tmp_path / "nan.pcd", bad)
    said: list[str] = []
    cloud = read_cloud(path, warn=said.append)
    assert len(cloud) == len(points) - 4 and np.all(np.isfinite(cloud.points))
    assert len(said) == 1 and "dropped 4 of 400" in said[0]
    keep = np.ones(len(points), bool)
    keep[[3, 10, 11, 20]] = False
    assert np.max(np.abs(cloud.points - points[keep])) < 1e-7
    with pytest.warns(CloudFileWarning, match="dropped 4"):
        read_cloud(ply_binary(tmp_path / "nan.ply", bad))


def test_a_cloud_of_nan_only_is_refused(tmp_path: Path, points: np.ndarray) -> None:
    path = ply_ascii(tmp_path / "nan.ply", np.full_like(points, np.nan))
    with pytest.raises(CloudFileError) as e:
        read_cloud(path)
    assert e.value.code is CloudFault.NOT_FINITE


@pytest.mark.parametrize(
    ("content", "code"),
    [
        (b"", CloudFault.EMPTY),
        (b"\n\r\n  \n", CloudFault.EMPTY),
        (b"hello, I am a text file\nnothing else\n", CloudFault.NOT_A_CLOUD),
        (b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4, CloudFault.NOT_A_CLOUD),
        (b"0 TABLES\n2 SECTION\n", CloudFault.NOT_A_CLOUD),  # a DXF by mistake
        (b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
         b"end_header\n", CloudFault.EMPTY),
        (b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
         b"end_header\n1 2 3\n4 5 6\n", CloudFault.MALFORMED),  # truncated (open3d returns garbage here)
        (b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
         b"end_header\n1 2 3\n4 five 6\n", CloudFault.MALFORMED),
        (b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float a\nproperty float b\nend_header\n1 2\n3 4\n",
         CloudFault.MALFORMED),
        (b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n", CloudFault.MALFORMED),  # no end_header
        (b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 0\nHEIGHT 1\nPOINTS 0\n"
         b"DATA ascii\n", CloudFault.EMPTY),
        (b"VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2\n",
         CloudFault.MALFORMED),
        (b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 9\nHEIGHT 1\nPOINTS 9\n"
         b"DATA binary\n" + bytes(12 * 5), CloudFault.MALFORMED),  # 5 of 9 rows
        (b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n"
         b"DATA zipped\n", CloudFault.UNSUPPORTED),
    ],
)  # fmt: skip
def test_bad_files_are_one_line_errors_with_their_code(tmp_path: Path, content: bytes, code: CloudFault) -> None:
    path = tmp_path / "bad.ply"
    path.write_bytes(content)
    with pytest.raises(CloudFileError) as e:
        read_cloud(path)
    assert e.value.code is code, e.value.message
    assert e.value.exit_code == 2 and e.value.path == str(path)
    assert "\n" not in e.value.message and "valid:" in e.value.message


def test_truncated_binary_files_are_refused(tmp_path: Path, points: np.ndarray) -> None:
    for path in (ply_binary(tmp_path / "t.ply", points), pcd_binary_compressed(tmp_path / "t.pcd", points)):
        path.write_bytes(path.read_bytes()[:-100])
        with pytest.raises(CloudFileError) as e:
            read_cloud(path)
        assert e.value.code is CloudFault.MALFORMED


def test_missing_file_bad_units_and_bad_frame(tmp_path: Path) -> None:
    with pytest.raises(CloudFileError) as e:
        read_cloud(tmp_path / "nowhere.pcd")
    assert e.value.code is CloudFault.MISSING
    with pytest.raises(CloudFileError) as e:
        read_cloud(tmp_path)
    assert e.value.code is CloudFault.MISSING and "folder" in e.value.message
    with pytest.raises(UsageError, match="valid: m, cm, mm, in"):
        read_cloud(tmp_path / "x.pcd", units="feet")
    with pytest.raises(UsageError, match="--frame"):
        read_cloud(tmp_path / "x.pcd", frame="base link")


@pytest.mark.skipif(not REAL_SCANS.is_dir(), reason=f"the real scans are not in {REAL_SCANS}")
def test_a_real_scan_reads_as_its_readme_says() -> None:
    """The lidar scan of the tee (PCD ascii, CRLF): its 65,205 points, in metres, around the README's placement."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing dropped
        cloud = read_cloud(REAL_SCANS / "table_8in10in_tee_x0y24.pcd")
    assert len(cloud) == 65205 and cloud.frame == "F"
    lo, hi = cloud.points.min(axis=0), cloud.points.max(axis=0)
    assert np.all(hi - lo < 1.0) and lo[1] < -0.6096 < hi[1]  # the part's nominal y, inside a table-sized cloud
