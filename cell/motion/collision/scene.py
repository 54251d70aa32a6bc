"""The obstacles of a welding cell in the robot base frame R: the aligned map's parts and the table."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.geometry import invert, make_pose
from cell.types import Box, Part, WeldMap


def cell_obstacles(
    weldmap_R: WeldMap,
    X_WR: npt.ArrayLike,
    table_center_W: npt.ArrayLike,
    table_size: npt.ArrayLike,
    table_name: str = "TABLE",
) -> tuple[Part, ...]:
    """The obstacles of a welding cell in R: the aligned map's parts (as perceived) and the table box, given by
    its centre in the world [m] and its size (3,) [m] (X_WR (4, 4): the robot base in the world)."""
    X_RW = invert(np.asarray(X_WR, dtype=float))
    table = Part(table_name, Box(X_RW @ make_pose(p=table_center_W), np.asarray(table_size, dtype=float)))
    return (*weldmap_R.parts, table)
