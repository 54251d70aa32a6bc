"""Depth images as 16-bit PNG files: integer depth units, 0 = invalid (the RealSense / ROS ``16UC1`` convention).

A depth z [m] is stored as ``round(z / depth_scale_m)``; reading gives ``float32(units * depth_scale_m)``, the same
float64 product then float32 cast the simulator's noise model quantises with (:mod:`cell.sim.noise`), so a depth
on the scale's grid comes back bit-identical. pillow is the only library that touches the files.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from cell.errors import CaptureError
from cell.outputs import replacing

MAX_UNITS = 65535  # the largest depth a 16-bit PNG holds, in depth units
MAX_PIXELS = 4096 * 4096  # the largest depth image read (a 5 Mpx structured-light camera is among the largest)


@dataclass(frozen=True)
class Encoded:
    """A depth image in depth units and what the encoding lost.

    units : (H, W) uint16 depth units (0 = invalid).
    off_grid : valid pixels whose depth was not a whole number of units (they come back rounded).
    max_rounding_m : the largest change rounding made to such a pixel [m] (at most half a unit).
    too_far : pixels beyond ``MAX_UNITS`` units, stored as invalid (0).
    not_finite : NaN, infinite or negative pixels, stored as invalid (0).
    """

    units: npt.NDArray[np.uint16]
    off_grid: int
    max_rounding_m: float
    too_far: int
    not_finite: int


def to_metres(units: npt.NDArray[np.uint16], depth_scale_m: float) -> npt.NDArray[np.float32]:
    """(H, W) float32 depth [m] from depth units (0 stays 0)."""
    return (units.astype(np.float64) * depth_scale_m).astype(np.float32)


def encode(depth_m: npt.ArrayLike, depth_scale_m: float) -> Encoded:
    """Depth [m] (H, W) -> depth units at ``depth_scale_m`` [m per unit], with what was lost (:class:`Encoded`)."""
    if not depth_scale_m > 0.0:
        raise ValueError(f"depth_scale_m must be > 0, got {depth_scale_m}")
    z = np.asarray(depth_m, dtype=np.float64)
    bad = ~np.isfinite(z) | (z < 0.0)
    z = np.where(bad, 0.0, z)
    n = np.round(z / depth_scale_m)
    far = n > MAX_UNITS
    n[far] = 0.0
    units = n.astype(np.uint16)
    ok = (units > 0) & ~far & ~bad
    back = to_metres(units, depth_scale_m)
    off = ok & (back != np.asarray(depth_m, dtype=np.float32))
    rounding = float(np.max(np.abs(back[off].astype(np.float64) - z[off]))) if off.any() else 0.0
    return Encoded(units, int(off.sum()), rounding, int(far.sum()), int(bad.sum()))


def write_png(path: Path, units: npt.NDArray[np.uint16]) -> None:
    """Write (H, W) uint16 depth units as a 16-bit greyscale PNG."""
    from PIL import Image

    # zlib level 1: a quarter of the default's time for 6 % more bytes (a 1280 x 720 depth image: ~0.95 MB)
    image = Image.fromarray(np.ascontiguousarray(units, dtype=np.uint16))
    with replacing(path, what="depth image") as tmp:
        image.save(tmp, format="PNG", compress_level=1)


def check_size(path: Path, width: int, height: int) -> None:
    """CaptureError unless a ``width`` x ``height`` image is within :data:`MAX_PIXELS`."""
    if width * height > MAX_PIXELS:
        raise CaptureError(
            f"depth image {path} would be {width} x {height} px ({width * height / 1e6:.3g} Mpx); valid: at most"
            f" {MAX_PIXELS / 1e6:.3g} Mpx (no depth camera has more)",
            path=str(path),
        )


def read_png(path: Path, size: tuple[int, int] | None = None) -> npt.NDArray[np.uint16]:
    """(H, W) uint16 depth units of a 16-bit greyscale PNG; CaptureError if it is missing, not a PNG, not 16-bit
    single-channel, over :data:`MAX_PIXELS` or not ``size`` (width, height) when given. The size is read from the
    PNG's header and checked before any pixel is decoded (a decompression bomb costs nothing)."""
    import warnings

    from PIL import Image, UnidentifiedImageError

    if not path.is_file():
        raise CaptureError(f"depth image {path} is missing; valid: the file capture.json names", path=str(path))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)  # the size is checked here, below
            im = Image.open(path)
        with im:
            fmt, mode = im.format, im.mode
            if fmt != "PNG":
                raise CaptureError(f"depth image {path} is {fmt or 'not an image'}; valid: a PNG", path=str(path))
            if mode not in ("I;16", "I;16B", "I;16L"):
                raise CaptureError(
                    f"depth image {path} has pixel mode {mode}; valid: 16-bit single-channel (I;16) depth units",
                    path=str(path),
                )
            if size is not None and im.size != size:
                raise CaptureError(
                    f"{path} is {im.size[0]} x {im.size[1]} px, its CameraInfo says {size[0]} x {size[1]}; valid:"
                    " the same size",
                    path=str(path),
                )
            check_size(path, *im.size)
            units = np.asarray(im, dtype=np.uint16)
    except CaptureError:
        raise
    except Image.DecompressionBombError:
        raise CaptureError(
            f"depth image {path} declares more pixels than Pillow decodes (a decompression bomb); valid: at most"
            f" {MAX_PIXELS / 1e6:.3g} Mpx",
            path=str(path),
        ) from None
    except UnidentifiedImageError:
        raise CaptureError(f"depth image {path} is not an image; valid: a 16-bit PNG", path=str(path)) from None
    except (OSError, SyntaxError, ValueError, EOFError) as e:  # truncated or corrupt data
        raise CaptureError(f"depth image {path} cannot be read ({e}); valid: a 16-bit PNG", path=str(path)) from None
    if units.shape != im.size[::-1]:  # pillow decoded something else than its header said
        raise CaptureError(
            f"depth image {path} decoded to {units.shape} where its header says {im.size}; valid: an intact PNG",
            path=str(path),
        )
    return units
