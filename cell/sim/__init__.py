"""The simulated cell, the only package that imports pybullet: the sensor model, cameras, faults and execution records
(numpy only), the arm and the cell. ``from cell.sim import SimCell`` imports pybullet only when the name is first
asked for."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from cell.types.execution import Event, Execution

if TYPE_CHECKING:
    from cell.sim.cell import SimCell
    from cell.sim.robot import BeadStyle, SimRobot

__all__ = ["BeadStyle", "Event", "Execution", "SimCell", "SimRobot"]


def __getattr__(name: str) -> Any:
    if name == "SimCell":
        from cell.sim.cell import SimCell

        return SimCell
    if name in ("BeadStyle", "SimRobot"):
        from cell.sim import robot

        return getattr(robot, name)
    raise AttributeError(f"module 'cell.sim' has no attribute {name!r}")
