"""The file inputs as strict as their use: each case an outsider found (a traceback, a blow-up, an inconsistent
file read without a word) refused in one line or read with a warning that counts what was done."""

from __future__ import annotations

import json
import resource
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from cloud_writers import box_surface, pcd_ascii, pcd_binary, pcd_binary_compressed, ply_ascii, ply_binary

from cell.errors import CaptureError, CloudFault, CloudFileError
from cell.geometry import look_at
from cell.perception.cloud_files import read_cloud
from cell.recorded import read_capture, write_capture
from cell.recorded.depth_png import MAX_PIXELS, read_png
from cell.types import CameraIntrinsics, DepthImage

WRITERS = {"pcd-binary": pcd_binary, "ply-binary": ply_binary, "ply-ascii": ply_ascii, "pcd-ascii": pcd_ascii}


@pytest.fixture
def points() -> np.ndarray:
    return box_surface(np.random.default_rng(3), 500, (0.3, 0.2, 0.1)) + np.array([0.5, -0.2, 0.05])


def refused(path: Path, code: CloudFault = CloudFault.MALFORMED) -> str:
    with pytest.raises(CloudFileError) as e:
        read_cloud(path)
    assert e.value.code is code and "\n" not in e.value.message and "valid:" in e.value.message
    return e.value.message


def test_a_negative_points_count_is_refused_with_or_without_a_stray_byte(tmp_path: Path, points: np.ndarray) -> None:
    data = pcd_binary(tmp_path / "a.pcd", points).read_bytes()
    for width in (b"WIDTH 500", b"WIDTH -1"):
        for tail in (b"", b"\x00"):
            bad = data.replace(b"POINTS 500", b"POINTS -1").replace(b"WIDTH 500", width) + tail
            (tmp_path / "neg.pcd").write_bytes(bad)
            assert "POINTS -1" in refused(tmp_path / "neg.pcd")


@pytest.mark.parametrize("layout", list(WRITERS))
def test_a_header_counting_half_the_rows_is_refused(tmp_path: Path, points: np.ndarray, layout: str) -> None:
    data = WRITERS[layout](tmp_path / "c", points).read_bytes()
    for old in (b"POINTS 500", b"WIDTH 500", b"element vertex 500"):  # POINTS and WIDTH agreeing: the body tells
        data = data.replace(old, old.replace(b"500", b"250"))
    (tmp_path / "half").write_bytes(data)
    message = refused(tmp_path / "half")
    assert "250" in message and ("rows" in message or "values" in message)


@pytest.mark.parametrize("writer", [pcd_binary, ply_binary, pcd_binary_compressed])
def test_stray_bytes_after_the_last_row_are_a_warning_and_whole_rows_an_error(
    tmp_path: Path, points: np.ndarray, writer: object
) -> None:
    path = writer(tmp_path / "c", points)  # type: ignore[operator]
    data = path.read_bytes()
    path.write_bytes(data + b"\n\x00\x07")
    said: list[str] = []
    assert len(read_cloud(path, warn=said.append)) == len(points)
    assert len(said) == 1 and "3 stray bytes" in said[0]
    path.write_bytes(data + bytes(100))  # more than a row of 29 bytes (or 37 for the PLY)
    assert "more rows" in refused(path)


def test_points_written_twice_are_merged_with_a_count(tmp_path: Path, points: np.ndarray) -> None:
    said: list[str] = []
    cloud = read_cloud(ply_binary(tmp_path / "twice.ply", np.vstack([points, points])), warn=said.append)
    assert len(cloud) == len(points) and np.array_equal(cloud.points, points)  # first rows kept, in file order
    assert len(said) == 1 and "merged 500 duplicated points of 1000" in said[0]


def test_one_stray_return_is_dropped_not_taken_for_millimetres(tmp_path: Path, points: np.ndarray) -> None:
    said: list[str] = []
    cloud = read_cloud(ply_ascii(tmp_path / "stray.ply", np.vstack([points, [[25.0, 0.0, 0.0]]])), warn=said.append)
    assert len(cloud) == len(points) and np.max(np.abs(cloud.points)) < 1.0
    assert len(said) == 1 and "dropped 1 of 501" in said[0] and "25 m" in said[0]
    near = np.vstack([points, [[1.2, -0.2, 0.05]]])  # 0.55 m beyond the part: still within the margin, kept
    assert len(read_cloud(ply_ascii(tmp_path / "near.ply", near), warn=said.append)) == len(near) and len(said) == 1
    assert "--units mm" in refused(ply_ascii(tmp_path / "mm.ply", points * 1e3), CloudFault.UNITS)  # still said


def test_an_integer_column_holding_fractions_is_refused(tmp_path: Path, points: np.ndarray) -> None:
    data = pcd_ascii(tmp_path / "c.pcd", points).read_bytes().replace(b"TYPE F F F F", b"TYPE F I F F")
    (tmp_path / "int.pcd").write_bytes(data)
    assert "'y' values are of type i4" in refused(tmp_path / "int.pcd")


def png_header_only(path: Path, width: int, height: int) -> Path:
    """A 16-bit PNG declaring ``width`` x ``height`` px, one row of data (what a reader sees before decoding)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(bytes(1 + 2 * width)))
        + chunk(b"IEND", b"")
    )
    return path


def test_a_decompression_bomb_and_a_huge_png_are_one_line_errors(tmp_path: Path) -> None:
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for side, what in ((14000, "decompression bomb"), (9500, "9500 x 9500 px")):
        with pytest.raises(CaptureError, match=what) as e:
            read_png(png_header_only(tmp_path / f"{side}.png", side, side))
        assert "\n" not in e.value.message and e.value.path.endswith(f"{side}.png")
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 50_000  # [KiB] nothing was decoded


def test_a_huge_camera_with_a_matching_camera_info_is_refused_before_decoding(tmp_path: Path) -> None:
    intr = CameraIntrinsics(32, 24, 30.0, 30.0, 15.5, 11.5)
    image = DepthImage("cam", np.full((24, 32), 1.5, np.float32), intr, look_at([0, 0, 2.0], [0, 0, 0]), "fixed")
    folder = write_capture(tmp_path / "cap", {"cam": image}, np.eye(4), provenance={})
    index = json.loads((folder / "capture.json").read_text())
    index["cameras"][0]["camera_info"].update(width=9500, height=9500)
    (folder / "capture.json").write_text(json.dumps(index))
    png_header_only(folder / "cam.depth.png", 9500, 9500)
    with pytest.raises(CaptureError, match=f"at most {MAX_PIXELS / 1e6:.3g} Mpx"):
        read_capture(folder)
    png_header_only(folder / "cam.depth.png", 40, 30)  # a PNG whose header disagrees with its CameraInfo
    index["cameras"][0]["camera_info"].update(width=32, height=24)
    (folder / "capture.json").write_text(json.dumps(index))
    with pytest.raises(CaptureError, match="40 x 30 px, its CameraInfo says 32 x 24"):
        read_capture(folder)
