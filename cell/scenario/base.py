"""The base of every scenario model: unknown keys are errors, values frozen, no NaN or infinity."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

Vec3 = tuple[float, float, float]
CELL_M = 100.0  # no point of a cell lies further than this from the world's origin [m]
Coord = Annotated[float, Field(ge=-CELL_M, le=CELL_M)]
Point3 = tuple[Coord, Coord, Coord]  # a point of the cell in the world [m]
Angle = Annotated[float, Field(ge=-360.0, le=360.0)]
Angles3 = tuple[Angle, Angle, Angle]  # roll, pitch, yaw [deg]
NonNeg = Annotated[float, Field(ge=0.0)]
Pos = Annotated[float, Field(gt=0.0)]


class Model(BaseModel):
    # Non-finite numbers (.nan, .inf in YAML) are rejected: they would turn poses into NaN (fuzzing found it).
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)
