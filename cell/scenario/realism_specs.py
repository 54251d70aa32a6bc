"""``simulation:`` options that make the simulated part and sensors more like real ones (docs/bodies.md section 7).

Every option is off (None or empty) by default: a scenario without them simulates the part as drawn with the
scenario's deviations, and the sensors by their noise model alone. All are seeded from the scenario's seed
(``Scenario.rng``). Lengths in millimetres, angles in degrees.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator

from cell.scenario.base import Model


class GapsSpec(Model):
    """Joint gaps that vary along a seam: at every junction the abutting part's end is cut out of square, so that
    its gap to the receiving face opens linearly from 0 at one edge of its end face to ``max_mm`` at the other,
    along the junction's most horizontal seam (which edge is closed: drawn from the seed, per junction)."""

    max_mm: Annotated[float, Field(gt=0.0, le=5.0)] = 2.0  # the gap's opening at the open edge [mm]


class TacksPresentSpec(Model):
    """Tack welds laid before the cell sees the part: a short fillet bead (a triangular prism in the corner between
    the two weld faces, both legs ``leg_mm``) at each end of every seam, ``length_mm`` long (at most half the
    seam). Rendered bodies only: never parts of the map."""

    length_mm: Annotated[float, Field(gt=0.0, le=100.0)] = 10.0  # each bead's length along its seam [mm]
    leg_mm: Annotated[float, Field(gt=0.0, le=20.0)] = 4.0  # both legs of the bead's fillet [mm]


class BowSpec(Model):
    """A part bent in a circular arc of sagitta ``mm`` over its length (its principal axis of largest spread),
    tessellated in ``segments`` pieces. ``toward``: the principal axis (``y``: 2nd, ``z``: 3rd) the arc bulges
    along, its sign the sign of ``mm``; None: the one of the two nearer the drawing's horizontal plane."""

    part: str  # the map's part (exactly, else ignoring case)
    mm: Annotated[float, Field(ge=-20.0, le=20.0)]  # the arc's sagitta [mm], signed, not 0
    toward: Literal["y", "z"] | None = None  # the principal axis it bulges along; None: the more horizontal
    segments: Annotated[int, Field(ge=2, le=256)] = 16  # flat pieces along the length

    @field_validator("mm")
    @classmethod
    def _nonzero(cls, v: float) -> float:
        if v == 0.0:
            raise ValueError("a bow's sagitta mm must not be 0 (leave the bow out instead)")
        return v


class SpecularDropoutSpec(Model):
    """Shiny steel under an active-stereo projector: a pixel whose surface faces the camera within ``within_deg``
    (the mirror direction of a projector beside the camera: the pattern is reflected away or saturates) drops out
    (0) with probability ``fraction``, drawn per image from the camera's own ``/specular`` stream."""

    within_deg: Annotated[float, Field(gt=0.0, le=45.0)] = 8.0  # incidence below which a pixel may drop [deg]
    fraction: Annotated[float, Field(ge=0.0, le=1.0)] = 0.7  # the probability that such a pixel drops
