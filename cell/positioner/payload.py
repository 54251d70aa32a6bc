"""The part's load on the positioner (docs/positioner.md, "The load"): its mass from its bodies' volumes and the
material's density, its centre of mass on the faceplate, and its weight's worst static moment about each axis over
the axes' range, checked against the positioner's ratings. Frames: F, the faceplate at home; SI units."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cell.errors import PositionerFault, PositionerLoadError
from cell.geometry import FloatArray
from cell.types import Part
from cell.types.positioner import TiltRotatePositioner

G_M_S2 = 9.81
STEEL_KG_M3 = 7850.0


@dataclass(frozen=True)
class PartLoad:
    """The clamped part's mass [kg], its centre of mass p_F (3,) [m] in F, and its weight's worst moment [N m]
    about the tilt axis (any rotation, the lever horizontal) and about the rotate axis (at the largest tilt the
    limits allow, up to 90 deg)."""

    mass_kg: float
    p_F: FloatArray
    tilt_torque_nm: float
    rotate_torque_nm: float


def part_load(parts_F: Sequence[Part], pos: TiltRotatePositioner, density_kg_m3: float = STEEL_KG_M3) -> PartLoad:
    """The load of ``parts_F`` (their bodies in F, solid, of one material) on ``pos``.

    In the tilting body's frame (on the tilt axis, z along the rotate axis) the centre of mass lies at
    (Rz(r) (x, y), z + d): its distance from the tilt axis is at most sqrt(x^2 + y^2 + (z + d)^2), reached as the
    rotate axis turns it square to the tilt axis; its distance from the rotate axis is sqrt(x^2 + y^2)."""
    vols = np.array([p.volume for p in parts_F], dtype=float)
    mass = float(density_kg_m3 * vols.sum())
    c = np.sum([v * p.center for v, p in zip(vols, parts_F, strict=True)], axis=0) / max(vols.sum(), 1e-12)
    rho = math.hypot(float(c[0]), float(c[1]))
    tilt_lever = math.hypot(rho, float(c[2]) + pos.faceplate_offset_m)
    t_max = min(math.pi / 2.0, max(abs(pos.tilt.q_min), abs(pos.tilt.q_max)))
    w = mass * G_M_S2
    return PartLoad(mass, np.asarray(c, dtype=float), w * tilt_lever, w * rho * math.sin(t_max))


def check_load(load: PartLoad, pos: TiltRotatePositioner) -> None:
    """Raise :class:`PositionerLoadError` when the part's mass or either moment is over the positioner's rating."""
    for code, value, rated, unit in (
        (PositionerFault.PAYLOAD, load.mass_kg, pos.payload_kg, "kg"),
        (PositionerFault.TILT_TORQUE, load.tilt_torque_nm, pos.tilt_torque_nm, "N m"),
        (PositionerFault.ROTATE_TORQUE, load.rotate_torque_nm, pos.rotate_torque_nm, "N m"),
    ):
        if value > rated:
            what = "mass" if code is PositionerFault.PAYLOAD else f"weight's moment about the {code.split('_')[0]} axis"
            raise PositionerLoadError(
                f"the part's {what} is {value:.1f} {unit}, over the positioner's rated {rated:.1f} {unit}: "
                f"valid is at most the rating (robot.positioner.{_KEY[code]}; a lighter part or one clamped nearer "
                f"the axes)",
                code=code,
                value=value,
                needed=rated,
            )


_KEY = {
    PositionerFault.PAYLOAD: "payload_kg",
    PositionerFault.TILT_TORQUE: "tilt_torque_nm",
    PositionerFault.ROTATE_TORQUE: "rotate_torque_nm",
}
