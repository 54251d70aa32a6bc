"""Bad capture folders (docs/capture.md), made from a seed, for the fuzz of ``read_capture``
(``bench_fuzz.py --kind captures``).

Each case is a small folder written by ``write_capture`` (one to three cameras of 16 to 96 px, a truth file and a
cell file or not) and then spoilt one way: a file missing, a PNG of the wrong size, a CameraInfo that disagrees
with its PNG, a huge image (a 9500 x 9500 PNG with a matching CameraInfo, a decompression bomb), a corrupt PNG, a
bad value in the index, flipped bytes. ``expect`` as in ``fuzz_clouds``: ``clean``, ``flag`` or ``any``.
"""

from __future__ import annotations

import json
import shutil
import struct
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

from cell.geometry import look_at, pose_from_xyz_rpy
from cell.recorded import write_capture
from cell.types import Box, CameraIntrinsics, DepthImage, Part


@dataclass(frozen=True)
class Case:
    """One fuzzed folder: ``name`` (mutation/index), where it is, what it must get (``expect``)."""

    name: str
    folder: Path
    expect: str  # clean | flag | any


def png_header_only(path: Path, width: int, height: int) -> None:
    """A 16-bit greyscale PNG that declares ``width`` x ``height`` px and holds one row: what a reader sees before
    it decodes (a full one of 9500 x 9500 px is an 812 KB file that decodes to 180 MB)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0)
    row = zlib.compress(bytes(1 + 2 * width))
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", row) + chunk(b"IEND", b""))


def base(rng: np.random.Generator, folder: Path) -> Path:
    """A valid capture folder of one to three small cameras looking at a part on a table."""
    images = {}
    for k in range(int(rng.integers(1, 4))):
        w, h = int(rng.integers(16, 97)), int(rng.integers(12, 73))
        f = float(rng.uniform(0.8, 1.2) * w)
        intr = CameraIntrinsics(w, h, f, f, (w - 1) / 2, (h - 1) / 2)
        z = np.round(rng.uniform(0.6, 2.5, (h, w)) / 1e-4) * 1e-4
        z[rng.random(z.shape) < 0.05] = 0.0
        eye = [float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(1.5, 2.5))]
        images[f"cam{k}"] = DepthImage(f"cam{k}", z.astype(np.float32), intr, look_at(eye, [0, 0, 0.9]), "fixed")
    X_WR = pose_from_xyz_rpy([0.1, -1.0, 0.9], [0.0, 0.0, float(rng.uniform(-1, 1))])
    truth = (Part("P", Box(pose_from_xyz_rpy([0, 0, 0.95], [0, 0, 0]), np.array([0.3, 0.1, 0.1]))),)
    return write_capture(
        folder, images, X_WR, truth_parts_W=truth if rng.random() < 0.5 else None,
        cell_yaml="name: fuzz\n" if rng.random() < 0.5 else None, provenance={"tool": "fuzz"}, warn=lambda _: None,
    )  # fmt: skip


def _index(folder: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads((folder / "capture.json").read_text())
    return data


def _save(folder: Path, data: dict[str, Any]) -> None:
    (folder / "capture.json").write_text(json.dumps(data))


def _camera(rng: np.random.Generator, data: dict[str, Any]) -> dict[str, Any]:
    cam: dict[str, Any] = data["cameras"][int(rng.integers(len(data["cameras"])))]
    return cam


Mutation = Callable[[np.random.Generator, Path], str]


def _mutations() -> dict[str, Mutation]:
    def clean(rng: np.random.Generator, folder: Path) -> str:
        return "clean"

    def missing(rng: np.random.Generator, folder: Path) -> str:
        data = _index(folder)
        names = ["capture.json", *(c["depth"] for c in data["cameras"])]
        names += [data[k] for k in ("truth", "cell") if data.get(k)]
        (folder / names[int(rng.integers(len(names)))]).unlink()
        return "flag"

    def png_size(rng: np.random.Generator, folder: Path) -> str:
        cam = _camera(rng, _index(folder))
        w, h = cam["camera_info"]["width"], cam["camera_info"]["height"]
        dw, dh = (int(rng.integers(-3, 4)) for _ in range(2))
        dw = dw or 1
        units = rng.integers(0, 30000, (h + dh, w + dw)).astype(np.uint16)
        Image.fromarray(units).save(folder / cam["depth"], format="PNG")
        return "flag"

    def info_size(rng: np.random.Generator, folder: Path) -> str:
        data = _index(folder)
        info = _camera(rng, data)["camera_info"]
        key = "width" if rng.random() < 0.5 else "height"
        info[key] = int(rng.choice([info[key] + 1, info[key] - 1, info[key] * 2, 100_000]))
        _save(folder, data)
        return "flag"

    def huge(rng: np.random.Generator, folder: Path) -> str:
        data = _index(folder)
        cam = _camera(rng, data)
        w, h = [(9500, 9500), (14000, 14000), (4097, 4097), (65535, 65535)][int(rng.integers(4))]
        png_header_only(folder / cam["depth"], w, h)
        if rng.random() < 0.7:  # a CameraInfo that matches: only the pixel limit stops it
            cam["camera_info"].update(width=w, height=h)
            cam["camera_info"]["K"][2], cam["camera_info"]["K"][5] = (w - 1) / 2, (h - 1) / 2
            _save(folder, data)
        return "flag"

    def corrupt_png(rng: np.random.Generator, folder: Path) -> str:
        cam = _camera(rng, _index(folder))
        png = folder / cam["depth"]
        raw = png.read_bytes()
        pick = int(rng.integers(5))
        if pick == 0:
            png.write_bytes(raw[: int(rng.integers(0, len(raw) - 13))])  # cut before IEND
        elif pick == 1:
            Image.fromarray(rng.integers(0, 255, (8, 8, 3), dtype=np.uint8)).save(png, format="PNG")
        elif pick == 2:
            Image.fromarray(rng.integers(0, 255, (8, 8), dtype=np.uint8)).save(png, format="JPEG")
        elif pick == 3:
            png.write_bytes(rng.bytes(len(raw)))
        else:
            flipped = bytearray(raw)
            for i in rng.integers(8, len(raw), 4):
                flipped[i] = int(rng.integers(0, 256))
            png.write_bytes(bytes(flipped))
            return "any"
        return "flag"

    def bad_value(rng: np.random.Generator, folder: Path) -> str:
        data = _index(folder)
        cam = _camera(rng, data)
        edits: list[Callable[[], None]] = [
            lambda: cam["camera_info"].update(width=str(cam["camera_info"]["width"])),
            lambda: cam["camera_info"].update(height=-cam["camera_info"]["height"]),
            lambda: cam["camera_info"].update(K=[float("nan")] * 9),
            lambda: cam["camera_info"].update(D=[0.1, 0, 0, 0, 0]),
            lambda: cam.update(depth_scale_m=float(rng.choice([-1e-4, 0.0, float("inf")]))),
            lambda: cam.update(X_RC=cam["X_RC"][:3]),
            lambda: cam.update(mount="ceiling"),
            lambda: cam.update(depth="../" + cam["depth"]),
            lambda: cam.update(name=next((c["name"] for c in data["cameras"] if c is not cam), None)),
            lambda: data.update(version=2),
            lambda: data.update(format="something-else"),
            lambda: data.update(cameras=[]),
            lambda: data.update(X_WR=[[1e308] * 4] * 4),
            lambda: data.pop("X_WR"),
        ]
        edits[int(rng.integers(len(edits)))]()
        _save(folder, data)
        return "flag"

    def index_bytes(rng: np.random.Generator, folder: Path) -> str:
        raw = bytearray((folder / "capture.json").read_bytes())
        if rng.random() < 0.4:
            (folder / "capture.json").write_bytes(bytes(raw[: int(rng.integers(0, len(raw) - 2))]))
            return "flag"
        for i in rng.integers(0, len(raw), int(rng.integers(1, 6))):
            raw[i] = int(rng.integers(0, 256))
        (folder / "capture.json").write_bytes(bytes(raw))
        return "any"

    def not_a_folder(rng: np.random.Generator, folder: Path) -> str:
        shutil.rmtree(folder)
        if rng.random() < 0.5:
            folder.write_bytes(b"not a folder")
        return "flag"

    return {f.__name__: f for f in (clean, missing, png_size, info_size, huge, corrupt_png, bad_value,
                                    index_bytes, not_a_folder)}  # fmt: skip


MUTATIONS = _mutations()


def cases(seed: int, count: int, tmp: Path) -> Iterator[Case]:
    """``count`` folders under ``tmp`` from ``seed``: every mutation in turn, each on a new random folder."""
    rng = np.random.default_rng(seed)
    names = list(MUTATIONS)
    for i in range(count):
        mutation = names[i % len(names)]
        folder = base(rng, tmp / f"cap{i}")
        expect = MUTATIONS[mutation](rng, folder)
        yield Case(f"{mutation}/{i}", folder, expect)
