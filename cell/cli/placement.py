"""Where a drawing lies in a brought cloud or capture: ``--place X,Y,Z,YAW`` and ``--place-rpy X,Y,Z,R,P,Y``.

Millimetres and degrees on the command line (the edge), a (4, 4) pose in metres inside: the nominal pose of the
drawing's origin M in the data's own frame F (``X_FM``). Yaw is about the frame's z; the full form is
roll-pitch-yaw about fixed x, y, z (:func:`cell.geometry.pose_from_xyz_rpy`).
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
import typer

from cell.errors import UsageError
from cell.geometry import FloatArray, pose_from_xyz_rpy

PlaceOpt = Annotated[
    str | None,
    typer.Option(
        "--place",
        help="Nominal pose of the drawing's origin in the data's frame: X,Y,Z,YAW (millimetres, degrees about z).",
    ),
]
PlaceRpyOpt = Annotated[
    str | None,
    typer.Option("--place-rpy", help="The full pose instead: X,Y,Z,ROLL,PITCH,YAW (millimetres, degrees)."),
]


def _numbers(text: str, option: str, count: int, form: str) -> list[float]:
    parts = [p.strip() for p in text.split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise UsageError(f"{option} {text!r}: not numbers; valid: {form}") from None
    if len(values) != count:
        raise UsageError(f"{option} {text!r}: {len(values)} values; valid: {form} ({count} values)")
    if not all(math.isfinite(v) for v in values):
        raise UsageError(f"{option} {text!r}: not finite; valid: {form}")
    return values


def placement(place: str | None, place_rpy: str | None) -> FloatArray | None:
    """``X_FM`` (4, 4) [m] from ``--place`` or ``--place-rpy`` (None when neither is given); both is a usage error."""
    if place is not None and place_rpy is not None:
        raise UsageError("--place and --place-rpy both given; valid: one of them")
    if place is not None:
        x, y, z, yaw = _numbers(place, "--place", 4, "X,Y,Z,YAW in mm and degrees")
        return pose_from_xyz_rpy(np.array([x, y, z]) * 1e-3, [0.0, 0.0, math.radians(yaw)])
    if place_rpy is not None:
        x, y, z, r, p, yaw = _numbers(place_rpy, "--place-rpy", 6, "X,Y,Z,ROLL,PITCH,YAW in mm and degrees")
        return pose_from_xyz_rpy(np.array([x, y, z]) * 1e-3, np.radians([r, p, yaw]))
    return None
