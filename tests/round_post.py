"""A small round part for the curved-seam tests: a post standing on a plate in front of the robot (its fillet a
CIRCLE, a T cylinder on plane), drawn with the round maps' generators, and the scenario around it (no noise, one
small camera that no test captures with)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from tools_loader import load_tool

from cell import scenario as scn

RADIUS_MM = 30.0
PLATE_MM = 10.0
SEAM = "POST>PLATE:circle"
_HEAD = """
name: {name}
seed: 7
simulation: {{noise: none}}
map: {{file: post.dxf, X_WM: {{xyz_m: [{x}, {y}, 0.90]}}}}
table: {{center_m: [0.0, 0.0, 0.85], size_m: [1.6, 1.2, 0.10]}}
robot:
  urdf: kr5_arc.urdf
  X_WR: {{xyz_m: [0.0, {robot_y}, 0.90]}}
  home_deg: [-90.0, -100.0, 100.0, 0.0, 45.0, 0.0]
"""  # the post on its plate and the robot in front of it: the head of the two .format templates below
SCENARIO = (
    _HEAD
    + """cameras:
  above:
    eye_m: [0.0, 0.0, 1.6]
    target_m: [0.0, 0.0, 0.9]
    resolution: [64, 48]
perception:
  workspace: {{min_m: [-0.5, -0.5, 0.905], max_m: [0.5, 0.5, 1.3]}}
"""
)
SEEN = (
    _HEAD
    + """cameras:
  front: {{eye_m: [0.0, -0.45, 1.35], target_m: [0.0, 0.0, 0.93], resolution: [160, 120]}}
  back_l: {{eye_m: [-0.4, 0.25, 1.35], target_m: [0.0, 0.0, 0.93], resolution: [160, 120]}}
  back_r: {{eye_m: [0.4, 0.25, 1.35], target_m: [0.0, 0.0, 0.93], resolution: [160, 120]}}{more}
perception:
  workspace: {{min_m: [-0.5, -0.5, 0.905], max_m: [0.5, 0.5, 1.3]}}
rescan: {{weld_tolerance_mm: {tol_mm}}}
"""
)
EYE_IN_HAND = """
  eye_in_hand: {{mount: eye_in_hand, eye_m: [0.0, {eye_y}, 1.5], target_m: [0.0, 0.0, 0.93], resolution: [320, 240]}}"""


def seen_scenario(
    folder: Path, name: str, tol_mm: float, *, eye_in_hand: bool = False, robot_y_m: float = -0.75
) -> scn.Scenario:
    """The post 0.75 m in front of the robot (``robot_y_m``: the robot's base at that y [m] in W, the post at 0)
    seen by three 160 x 120 cameras (they state about 0.18 mm sigma on its fillet), with the arm's camera too if
    asked, and the weld tolerance ``tol_mm``."""
    return scn.load(seen_yaml(folder, name, tol_mm, eye_in_hand=eye_in_hand, robot_y_m=robot_y_m))


def seen_yaml(folder: Path, name: str, tol_mm: float, *, eye_in_hand: bool = False, robot_y_m: float = -0.75) -> Path:
    """:func:`seen_scenario`'s file (``folder/<name>.yaml`` beside its map), for the command line."""
    post_map(folder / "post.dxf")
    path = folder / f"{name}.yaml"
    more = EYE_IN_HAND.format(eye_y=robot_y_m + 0.45) if eye_in_hand else ""  # 0.45 m on from the base
    path.write_text(SEEN.format(name=name, x=0.0, y=0.0, robot_y=robot_y_m, more=more, tol_mm=tol_mm))
    return path


def post_map(path: Path, height_mm: float = 80.0) -> Path:
    """``path`` written as a DXF: a 60 mm post ``height_mm`` tall (48 facets) on a 200 x 200 x 10 plate, its fillet a
    red CIRCLE with the id :data:`SEAM`."""
    rm = load_tool("round_meshes")
    mk = load_tool("make_round")
    maps = load_tool("make_maps")
    m = mk._Map()
    m.body("PLATE", maps.box_mesh((-100.0, -100.0, 0.0), (100.0, 100.0, PLATE_MM)))
    flat = (lambda x, y: PLATE_MM), (lambda x, y: PLATE_MM + height_mm)
    m.body("POST", rm.tube_mesh(RADIUS_MM, RADIUS_MM - 4.0, 48, *flat, np.eye(4)))
    rm.add_circle_seam(m.msp, SEAM, (0.0, 0.0, PLATE_MM), RADIUS_MM, (0.0, 0.0, 1.0), mk.SEAM_LAYER)
    m.doc.saveas(path)
    return path


def post_scenario(folder: Path, x_m: float = 0.0, y_m: float = 0.0) -> scn.Scenario:
    """The scenario of a post on a plate at (x_m, y_m) on the table [m], the robot 0.75 m in front of it."""
    post_map(folder / "post.dxf")
    return scn.from_yaml(SCENARIO.format(name="round-post", x=x_m, y=y_m, robot_y=-0.75), base_dir=folder)


__all__ = ["RADIUS_MM", "SEAM", "post_map", "post_scenario", "seen_scenario", "seen_yaml"]
