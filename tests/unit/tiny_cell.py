"""A tiny welding cell shared by the motion tests: the KR 5 arc, a table, a rail and a post abutting it.

The robot base R sits at table-top height (z = 0 is the table top); the rail lies 0.92 m in front of it and the post
abuts the rail's near face (y = ``Y`` = 0.87) across a 1 mm gap. Seams are given as (id, start, end, n_a, n_b) so
each test wraps them in the value type it exercises.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cell.geometry import make_pose
from cell.types import Box, Part

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"
HOME = np.radians([-90.0, -100.0, 100.0, 0.0, 45.0, 0.0])
TABLE = Part("TABLE", Box(make_pose(p=[0.0, 1.05, -0.05]), np.array([2.0, 1.2, 0.1])))
RAIL = Part("RAIL", Box(make_pose(p=[0.0, 0.92, 0.03]), np.array([0.4, 0.1, 0.06])))
POST = Part("POST", Box(make_pose(p=[0.0, 0.769, 0.03]), np.array([0.06, 0.2, 0.06])))
OBSTACLES = (TABLE, RAIL, POST)
Y = 0.87
# The post's top seam (along x) and its right side seam (vertical), both on the rail's near face.
TOP_SEAM = ("top", np.array([-0.03, Y, 0.06]), np.array([0.03, Y, 0.06]), np.array([0, 0, 1.0]), np.array([0, -1.0, 0]))
SIDE_SEAM = ("side", np.array([0.03, Y, 0.0]), np.array([0.03, Y, 0.06]), np.array([1.0, 0, 0]), np.array([0, -1.0, 0]))
