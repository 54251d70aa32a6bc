"""Geometry a run computes once and hands on: the obstacles the arm must miss and their collision checker.

The joints of the map are found once per run too (:func:`cell.pipeline.detect.capture`): they are topological
(which face of which part), so the same joints hold for the map as drawn, as aligned and as built.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from cell.pipeline.records import Detection
from cell.station import Arm
from cell.types import Part

if TYPE_CHECKING:
    from cell.motion.collision import CollisionChecker


@dataclass(frozen=True)
class MotionScene:
    """What the arm must miss, in R: the aligned map's parts and the table, and the checker built on them (it
    loads the arm's collision model once for the whole run: planning, the gate and every re-scan view)."""

    obstacles: tuple[Part, ...]
    checker: CollisionChecker


def motion_scene(arm: Arm, det: Detection) -> MotionScene:
    """The obstacles of a detection's aligned map (its nominal placement when alignment failed) and the table."""
    from cell.motion.collision import CollisionChecker
    from cell.motion.collision.scene import cell_obstacles

    sc = det.scenario
    obstacles = cell_obstacles(det.weldmap_R, sc.X_WR, sc.table.center_m, sc.table.size_m)
    obstacles = (*obstacles, *det.weldmap_R.fixtures)  # clamps and stops (map.layers): obstacles, never parts
    return MotionScene(obstacles, CollisionChecker(arm.model, obstacles, sc.motion.plan.collision))
