"""The base of every scenario model: unknown keys are errors, values frozen, no NaN or infinity."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

Vec3 = tuple[float, float, float]
NonNeg = Annotated[float, Field(ge=0.0)]
Pos = Annotated[float, Field(gt=0.0)]


class Model(BaseModel):
    # Non-finite numbers (.nan, .inf in YAML) are rejected: they would turn poses into NaN (fuzzing found it).
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)
