"""What the safety gate found: a violation, typed (:class:`ViolationKind`) with where and by how much. The gate
(:mod:`cell.gate`) makes them; the run's record and its report carry them as they are."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum


class ViolationKind(StrEnum):
    """What a violation is about (the first word of its text)."""

    START_STATE = "start_state"
    POSITION = "position"
    VELOCITY = "velocity"
    ACCELERATION = "acceleration"
    JERK = "jerk"
    JUMP = "jump"
    SINGULARITY = "singularity"
    ARC = "arc"
    COLLISION = "collision"
    BODY = "body"  # the TCP or the wire inside a part's body


@dataclass(frozen=True)
class Violation:
    """One problem: kind (start_state | position | velocity | acceleration | jerk | jump | singularity | arc |
    collision | body), a one-line description, where (time t [s], joint name or ""), and by how much (``excess`` in
    the kind's SI unit: rad, rad/s, rad/s^2, rad/s^3, m^3 for manipulability, m for collision and body depth).
    seam_id, body : the seam whose motion it is and the part it enters ("" when the check does not say)."""

    kind: ViolationKind
    what: str
    t: float
    joint: str = ""
    excess: float = 0.0
    seam_id: str = ""
    body: str = ""

    def __str__(self) -> str:
        j = f" {self.joint}" if self.joint else ""
        return f"{self.kind}{j} at t = {self.t:.3f} s: {self.what}"
