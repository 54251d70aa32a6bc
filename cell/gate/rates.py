"""Velocity, acceleration and jerk limits at every sample of the plan re-sampled at ``rate_hz`` (jerk: the finite
difference of the re-sampled acceleration). ``rel_tol`` (1 %) covers rounding and the quintic interpolation of
a plan stored coarser than the gate's rate."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cell.gate.base import DEG, GateInput, Violation, ViolationKind
from cell.geometry import FloatArray


def _worst(
    kind: ViolationKind, times: FloatArray, values: FloatArray, limit: FloatArray, names: tuple[str, ...], unit: str
) -> list[Violation]:
    """Per joint, the sample where |value| exceeds limit the most."""
    out = []
    excess = np.abs(values) - limit
    for j in np.flatnonzero(np.any(excess > 0.0, axis=0)):
        i = int(np.argmax(excess[:, j]))
        out.append(
            Violation(
                kind,
                f"|{kind}| {abs(values[i, j]) * DEG:.4g} {unit} over the limit "
                f"{limit[j] * DEG:.4g} {unit} by {excess[i, j] * DEG:.3g} {unit}",
                float(times[i]),
                names[j],
                float(excess[i, j]),
            )
        )
    return out


@dataclass(frozen=True)
class VelocityLimit:
    """Per joint: the sample over v_max (1 + rel_tol) the most."""

    def violations(self, gate: GateInput) -> list[Violation]:
        rs, lim, k = gate.resampled, gate.robot.limits, 1.0 + gate.options.rel_tol
        return _worst(ViolationKind.VELOCITY, rs.t, rs.qd, lim.v_max * k, gate.robot.joint_names, "deg/s")


@dataclass(frozen=True)
class AccelerationLimit:
    """Per joint: the sample over a_max (1 + rel_tol) the most."""

    def violations(self, gate: GateInput) -> list[Violation]:
        rs, lim, k = gate.resampled, gate.robot.limits, 1.0 + gate.options.rel_tol
        return _worst(ViolationKind.ACCELERATION, rs.t, rs.qdd, lim.a_max * k, gate.robot.joint_names, "deg/s^2")


@dataclass(frozen=True)
class JerkLimit:
    """Per joint: the sample over j_max (1 + rel_tol) the most."""

    def violations(self, gate: GateInput) -> list[Violation]:
        rs, lim, k = gate.resampled, gate.robot.limits, 1.0 + gate.options.rel_tol
        return _worst(ViolationKind.JERK, rs.t[1:], rs.qddd, lim.j_max * k, gate.robot.joint_names, "deg/s^3")
