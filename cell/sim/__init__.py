"""The simulated cell: the only package that imports pybullet.

- :mod:`cell.sim.noise`: depth-sensor error model (numpy only).
- :mod:`cell.sim.camera`: pinhole intrinsics <-> OpenGL matrices, depth-buffer linearisation (numpy only).
- :mod:`cell.sim.faults`: broken cameras, objects the map does not know, parts not built (numpy only).
- :mod:`cell.sim.execution`: :class:`Execution`, what playing back a trajectory recorded (numpy only).
- :mod:`cell.sim.robot`: :class:`SimRobot`, the arm in the PyBullet client, and the weld bead.
- :mod:`cell.sim.cell`: :class:`SimCell`, which owns a PyBullet client, builds the cell and renders cameras.
- :mod:`cell.sim.asbuilt`: the part as really built, the simulation's ground truth (numpy only).

``from cell.sim import SimCell`` (or ``SimRobot``, ``BeadStyle``) imports pybullet only when the name is first
asked for; the numpy-only names are imported with the package.
"""

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
