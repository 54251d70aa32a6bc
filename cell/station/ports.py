"""The station's ports: what the pipeline may ask of a running cell, whatever drives it (the simulator, a recording,
a real cell), as Drake's hardware station offers the same ports for simulation and hardware: capture, a close-up
capture, execute, joint state, the turn, the truth (docs/architecture.md, "A station"). Frames: W, R; SI units."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy.typing as npt

from cell.geometry import FloatArray
from cell.types import CameraIntrinsics, DepthImage, Part

if TYPE_CHECKING:
    from cell.motion.robot import RobotModel
    from cell.types.execution import Execution


@dataclass(frozen=True)
class Arm:
    """The robot of the station: its model, home and scan configurations (dof,) [rad]."""

    model: RobotModel
    q_home: FloatArray
    q_scan: FloatArray


class Station(Protocol):
    """The ports of a running cell (module docstring). Use as a context manager; :meth:`close` releases it."""

    @property
    def arm(self) -> Arm | None:
        """The robot, or None for a cell without one (cameras only)."""
        ...

    @property
    def source(self) -> str:
        """Where its images come from: ``simulation`` (rendered now, with the scenario's noise), ``capture`` (a
        recorded folder) or ``camera`` (a real cell's)."""
        ...

    def capture(self) -> Mapping[str, DepthImage]:
        """One depth image from every camera, by name; the arm (if any) first goes to its scan configuration."""
        ...

    def capture_eye_in_hand(self, camera: str) -> DepthImage:
        """One depth image from the arm's camera ``camera`` where the arm is now (its pose from the kinematics)."""
        ...

    def intrinsics(self, camera: str) -> CameraIntrinsics:
        """The pinhole intrinsics of ``camera``."""
        ...

    def execute(
        self,
        times: npt.ArrayLike,
        q: npt.ArrayLike,
        arc_on: npt.ArrayLike,
        *,
        marks: Sequence[tuple[float, str]] = (),
        record_dt: float = 0.01,
        bead: bool = True,
        e1: npt.ArrayLike | None = None,
    ) -> Execution:
        """Drive the arm along times (n,) [s], q (n, dof) [rad], arc on (n,) bool; record the tool.

        marks (time [s], text) are logged as events; ``bead`` lays the weld where the arc is on (a move with the
        arc off lays none either way). e1 : (n,) [m] the linear track's E1 at each time (the base rides along,
        docs/track.md), None: the base stays. The arm stays at the last configuration.
        """
        ...

    def turn_part(self, X_W_turn: FloatArray) -> None:
        """Have the part turned over (an operator's job) by the nominal rigid motion X_W_turn (4, 4) in W and
        set down again; where it really lies is for a new capture to find. A station that cannot (a recording)
        raises :class:`~cell.errors.UsageError`."""
        ...

    def joint_state(self) -> FloatArray:
        """(dof,) [rad]: where the arm is now."""
        ...

    def truth(self) -> tuple[Part, ...] | None:
        """The parts as built, in W, when the station knows them (for measuring, never for perception)."""
        ...

    def close(self) -> None:
        """Release the station (idempotent)."""
        ...

    def __enter__(self) -> Station: ...

    def __exit__(self, *exc: object) -> None: ...
