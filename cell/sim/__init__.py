"""The simulated cell: the only package that imports pybullet.

- :mod:`cell.sim.noise`: depth-sensor error model (numpy only).
- :mod:`cell.sim.camera`: pinhole intrinsics <-> OpenGL matrices, depth-buffer linearisation (numpy only).
- :mod:`cell.sim.cell`: :class:`SimCell`, which owns a PyBullet client, builds the cell and renders cameras.

``from cell.sim import SimCell`` imports pybullet only when ``SimCell`` is first asked for.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cell.sim.cell import SimCell

__all__ = ["SimCell"]


def __getattr__(name: str) -> Any:
    if name == "SimCell":
        from cell.sim.cell import SimCell

        return SimCell
    raise AttributeError(f"module 'cell.sim' has no attribute {name!r}")
