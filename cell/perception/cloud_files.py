"""Point cloud files people bring (``cell locate CLOUD``): PLY or PCD, ASCII or binary, known by content, read into a
:class:`Cloud` in metres; implausible sizes and unusable files refused with a :class:`~cell.errors.CloudFileError`,
NaN rows, duplicated rows and stray returns far from the cloud's bulk dropped with a warning line (docs/locate.md,
"What it reads")."""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import numpy.typing as npt

from cell.errors import CloudFault, CloudFileError, UsageError
from cell.perception._cloud_formats import Body, parse_pcd, parse_ply
from cell.types import Cloud

UNITS: dict[str, float] = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}  # metres per unit of the file
PLAUSIBLE_M = 20.0  # [m] no cloud of a weld cell reaches (or spans) this far from its frame's origin
SMALLEST_M = 1e-3  # [m] a cloud spanning less than this cannot show a part
FEW = 10  # points: fewer have no bulk to tell stray returns from
BULK = 0.01  # the cloud's bulk: per axis, between the quantiles BULK and 1 - BULK (stray returns left out)
FAR_MARGIN_M = 1.0  # [m] a point this far (or the bulk's span, if larger) outside the bulk's box is a stray return
_FRAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


class CloudFileWarning(UserWarning):
    """Something of a brought cloud file was dropped or read past (rows with NaN or infinite coordinates, duplicated
    rows, stray returns far from the rest, stray bytes after the last row)."""


def check_units(units: str) -> float:
    """Metres per unit of ``units`` (``m``, ``cm``, ``mm``, ``in``); UsageError for anything else."""
    if units not in UNITS:
        raise UsageError(f"--units {units!r}; valid: {', '.join(UNITS)}")
    return UNITS[units]


def check_frame(frame: str) -> str:
    """``frame`` if it is a frame name (a letter, then letters, digits or ``_``); UsageError otherwise."""
    if not _FRAME.match(frame):
        raise UsageError(f"--frame {frame!r}; valid: a frame name such as F or R (a letter, then letters or digits)")
    return frame


def _sniff(path: Path, head: bytes) -> str:
    """``ply`` or ``pcd`` from the first bytes of the file; CloudFileError when it is neither."""
    first = head.split(b"\n", 1)[0].rstrip(b"\r")
    if first == b"ply":
        return "ply"
    for raw in head.split(b"\n"):
        line = raw.strip()
        if not line or line.startswith(b"#"):
            continue
        if line.split()[0] in (b"VERSION", b"FIELDS"):
            return "pcd"
        break
    shown = first[:40].decode("ascii", errors="replace")
    raise CloudFileError(
        f"point cloud {str(path)!r} is neither PLY nor PCD (it starts with {shown!r}); valid: a PLY file (first"
        " line 'ply') or a PCD file (header VERSION, FIELDS, ... DATA)",
        code=CloudFault.NOT_A_CLOUD,
        path=str(path),
    )


def _points(path: Path, body: Body) -> npt.NDArray[np.float64]:
    if body.compressed:  # PCD binary_compressed: the sizes are checked, open3d decodes the LZF body
        from cell.perception import _open3d

        points = _open3d.read_pcd(path)
        if len(points) != body.count:
            raise CloudFileError(
                f"point cloud {str(path)!r}: open3d decoded {len(points)} points of the {body.count} its header"
                " states; valid: an intact binary_compressed PCD (or save it as ascii or binary)",
                code=CloudFault.MALFORMED,
                path=str(path),
            )
        return points
    assert body.xyz is not None
    return body.xyz


def read_cloud(
    path: str | Path, *, units: str = "m", frame: str = "F", warn: Callable[[str], None] | None = None
) -> Cloud:
    """The points of a PLY or PCD file as a :class:`Cloud` in ``frame``, in metres.

    path : the file (its format is known by content; see the module docstring for what is read and refused).
    units : the unit of the file's numbers: ``m`` (default), ``cm``, ``mm`` or ``in``.
    frame : the name of the data's own frame (``F`` by default: the frame the file's coordinates are in).
    warn : called with one line for each thing dropped or read past (default: a :class:`CloudFileWarning`).

    Returns points (n, 3) [m] in ``frame``, finite, distinct, near the bulk, in file order, with no camera index
    (-1).
    Raises :class:`~cell.errors.CloudFileError` (exit 2) for a file that cannot be used, and
    :class:`~cell.errors.UsageError` for unknown ``units`` or a bad ``frame`` name.
    """
    path = Path(path)
    scale = check_units(units)
    check_frame(frame)
    if not path.is_file():
        what = "is a folder" if path.is_dir() else "does not exist"
        raise CloudFileError(
            f"point cloud {str(path)!r} {what}; valid: a PLY or PCD file", code=CloudFault.MISSING, path=str(path)
        )
    data = path.read_bytes()
    if not data.strip():
        raise CloudFileError(
            f"point cloud {str(path)!r} is empty ({len(data)} bytes); valid: a PLY or PCD file with points",
            code=CloudFault.EMPTY,
            path=str(path),
        )
    kind = _sniff(path, data[:4096])
    body = parse_ply(path, data) if kind == "ply" else parse_pcd(path, data)
    if body.count == 0:
        raise CloudFileError(
            f"point cloud {str(path)!r} holds no points (its {kind.upper()} header says 0); valid: a cloud with points",
            code=CloudFault.EMPTY,
            path=str(path),
        )
    xyz = _points(path, body)
    say = warn or _warning
    for note in body.notes:
        say(note)
    finite = np.all(np.isfinite(xyz), axis=1)
    kept = int(finite.sum())
    if kept == 0:
        raise CloudFileError(
            f"point cloud {str(path)!r}: all {len(xyz)} points have NaN or infinite coordinates; valid: a cloud with"
            " finite points",
            code=CloudFault.NOT_FINITE,
            path=str(path),
        )
    if kept < len(xyz):
        say(f"point cloud {str(path)!r}: dropped {len(xyz) - kept} of {len(xyz)} points (NaN or infinite)")
    xyz = xyz[finite]
    first = np.sort(np.unique(xyz, axis=0, return_index=True)[1])  # each distinct row where it first appears
    if len(first) < len(xyz):
        say(
            f"point cloud {str(path)!r}: merged {len(xyz) - len(first)} duplicated points of {len(xyz)} (rows written"
            f" more than once; {len(first)} distinct points kept)"
        )
        xyz = xyz[first]
    p_F = xyz * scale
    lo_F, hi_F = bulk_box(p_F)
    check_plausible(lo_F, hi_F, path, units)
    far = far_from_bulk(p_F, lo_F, hi_F)
    if far.any():
        reach = float(np.max(np.linalg.norm(p_F[far], axis=1)))
        say(
            f"point cloud {str(path)!r}: dropped {int(far.sum())} of {len(p_F)} points far from the rest (beyond"
            f" {_margin(lo_F, hi_F):.3g} m of its bulk or {PLAUSIBLE_M:g} m of its origin; the farthest {reach:.4g} m"
            " from the origin): stray returns"
        )
        p_F = p_F[~far]
    return Cloud(p_F, frame)


def _warning(msg: str) -> None:
    warnings.warn(msg, CloudFileWarning, stacklevel=3)


def bulk_box(p_F: npt.NDArray[np.float64]) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The box (lo, hi) (3,) [m] of the cloud's bulk: per axis the quantiles :data:`BULK` and 1 - :data:`BULK`,
    taken inward (a point at either end is never in them); a cloud of under :data:`FEW` points is all bulk."""
    if len(p_F) < FEW:
        return p_F.min(axis=0), p_F.max(axis=0)
    lo = np.quantile(p_F, BULK, axis=0, method="higher")
    hi = np.quantile(p_F, 1.0 - BULK, axis=0, method="lower")
    return lo, np.maximum(lo, hi)


def _margin(lo_F: npt.NDArray[np.float64], hi_F: npt.NDArray[np.float64]) -> float:
    return max(FAR_MARGIN_M, float(np.max(hi_F - lo_F)))


def far_from_bulk(
    p_F: npt.NDArray[np.float64], lo_F: npt.NDArray[np.float64], hi_F: npt.NDArray[np.float64]
) -> npt.NDArray[np.bool_]:
    """Which points (n,) are stray returns: beyond the bulk's box grown by the larger of :data:`FAR_MARGIN_M` and
    the bulk's span, or beyond :data:`PLAUSIBLE_M` from the origin."""
    margin = _margin(lo_F, hi_F)
    outside = np.any((p_F < lo_F - margin) | (p_F > hi_F + margin), axis=1)
    return outside | (np.max(np.abs(p_F), axis=1) > PLAUSIBLE_M)


def check_plausible(lo_F: npt.NDArray[np.float64], hi_F: npt.NDArray[np.float64], path: Path, units: str) -> None:
    """Refuse a cloud whose bulk (box ``lo_F``, ``hi_F`` [m], :func:`bulk_box`) no weld cell's cloud has: beyond
    :data:`PLAUSIBLE_M` from the origin or across, or spanning less than :data:`SMALLEST_M`. The message says which
    ``--units`` would fix it. Judged on the bulk, so one stray return does not make metres look like millimetres."""
    reach = float(np.max(np.maximum(np.abs(lo_F), np.abs(hi_F))))
    span = float(np.max(hi_F - lo_F))
    size = max(reach, span)
    if size > PLAUSIBLE_M:
        if units == "m" and size * UNITS["mm"] <= PLAUSIBLE_M:
            hint = "looks like millimetres: pass --units mm"
        else:
            hint = "check --units"
        raise CloudFileError(
            f"point cloud {str(path)!r}: its bulk (98 % of the points per axis) spans {span:.4g} m and reaches"
            f" {reach:.4g} m from its origin read in {units}, beyond {PLAUSIBLE_M:g} m: {hint}; valid: --units"
            f" {', '.join(UNITS)}",
            code=CloudFault.UNITS,
            path=str(path),
        )
    if span < SMALLEST_M:
        hint = "if the file is in metres, drop --units" if units != "m" else "a single spot, not a part"
        raise CloudFileError(
            f"point cloud {str(path)!r}: its bulk (98 % of the points per axis) spans only {span * 1e3:.3g} mm read"
            f" in {units} ({hint}); valid: a cloud at least {SMALLEST_M * 1e3:g} mm across",
            code=CloudFault.UNITS,
            path=str(path),
        )
