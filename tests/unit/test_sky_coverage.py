"""The parts-seen check judges a part by the samples of its top open to the sky (cell/perception/sky.py): an open
tube's inner bottom wall faces up but lies under the tube's own top wall, where no camera above the table sees."""

from __future__ import annotations

import numpy as np

from cell import scenario as sc
from cell.geometry import make_pose
from cell.perception import part_coverage
from cell.perception.sky import open_to_sky
from cell.types import Box, Cloud, Part, Polyhedron, WeldMap

SIDE, WALL, LENGTH = 0.06, 0.004, 0.3  # [m]


def open_tube() -> Polyhedron:
    """A square hollow section along x, open at both ends, lying on z = 0: outer and inner shells joined by a ring
    of four quads at each end (outward normals; the inner shell faces the hollow)."""
    outer = [(0.0, 0.0), (SIDE, 0.0), (SIDE, SIDE), (0.0, SIDE)]  # (y, z), counter-clockwise seen from +x
    inner = [(WALL, WALL), (SIDE - WALL, WALL), (SIDE - WALL, SIDE - WALL), (WALL, SIDE - WALL)]
    v = [(x, y, z) for ring in (outer, inner) for x in (0.0, LENGTH) for y, z in ring]
    o0, o1, i0, i1 = 0, 4, 8, 12
    faces: list[tuple[int, ...]] = []
    for p in range(4):
        q = (p + 1) % 4
        faces += [
            (o0 + p, o0 + q, o1 + q, o1 + p),  # outer shell
            (i0 + p, i1 + p, i1 + q, i0 + q),  # inner shell, facing the hollow
            (o1 + p, o1 + q, i1 + q, i1 + p),  # end ring at x = LENGTH
            (o0 + q, o0 + p, i0 + p, i0 + q),  # end ring at x = 0
        ]
    return Polyhedron(np.array(v, dtype=float), tuple(faces))


def test_a_tubes_inner_bottom_is_not_open_to_the_sky() -> None:
    tube = Part("TUBE", open_tube())
    beside = Part("BOX", Box(make_pose(p=(0.15, 0.2, 0.02)), np.array([0.1, 0.1, 0.04])))
    p = np.array(
        [
            [0.15, 0.03, SIDE],  # the tube's top
            [0.15, 0.03, WALL],  # its inner bottom wall, under the top wall
            [0.15, 0.2, 0.04],  # the box's top beside it
            [0.15, 0.03, -0.01],  # under the tube
        ]
    )
    assert open_to_sky(p, [tube, beside]).tolist() == [True, False, True, False]


def test_a_tube_seen_from_above_covers_its_top() -> None:
    """The cloud holds the tube's outer top only, as cameras above see it: judged by what is open to the sky, the
    whole top is covered (with its inner bottom wall counted the share was about a half)."""
    weldmap = WeldMap((Part("TUBE", open_tube()),), (), "mm", "test", "R")
    y, x = np.meshgrid(np.arange(0.0, SIDE, 0.002), np.arange(0.0, LENGTH, 0.002))
    top = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, SIDE)])
    coverage = part_coverage(weldmap, Cloud(top, "R"), sc.load("fence1").perception)
    assert coverage["TUBE"] > 0.97
