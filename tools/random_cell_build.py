"""What the simulation does to a random weldment (``tools/random_cells.py``): the realism options and the build
deviations, drawn from the caller's generator, as the scenario's ``simulation`` keys.

The deviations stay within the paper's industrial tolerances (docs/trust.md section 1): a part's width and height
up to 1 %, its length up to 5 %, its location up to 1 %.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from random_cell_layouts import Design
from random_cell_parts import Body, rot_z
from random_cell_scene import r6

from cell.geometry import matrix_to_rpy
from cell.sim.asbuilt.shapes import principal_frame
from cell.types import Polyhedron, WeldMap

TOL_SECTION, TOL_LENGTH, TOL_LOCATION = 0.01, 0.05, 0.01
YAW_DEG = 0.3  # a member's turn about the vertical as built [deg]
MOVE_MM = 2.0  # the most a member moves as built [mm]


def realism(rng: np.random.Generator) -> dict[str, Any]:
    """The ``simulation`` keys of a random cell but its deviations: noise realistic (4 in 5) or none, the operator's
    placement error (up to 5 mm, 0.5 deg), gaps varying to 0.5-2 mm and tacks at the seam ends half the time each,
    specular dropout on shiny faces three times in ten."""
    sim: dict[str, Any] = {"noise": "realistic" if rng.random() < 0.8 else "none"}
    sim["placement_error"] = {
        "xyz_m": [r6(rng.uniform(-0.005, 0.005)), r6(rng.uniform(-0.005, 0.005)), 0.0],
        "rpy_deg": [0.0, 0.0, r6(rng.uniform(-0.5, 0.5))],
    }
    if rng.random() < 0.5:
        sim["gaps"] = {"max_mm": r6(rng.uniform(0.5, 2.0))}
    if rng.random() < 0.5:
        sim["tacks_present"] = {"length_mm": r6(rng.uniform(6, 12)), "leg_mm": r6(rng.uniform(3, 5))}
    if rng.random() < 0.3:
        sim["specular_dropout"] = {"within_deg": r6(rng.uniform(5, 10)), "fraction": r6(rng.uniform(0.3, 0.8))}
    return sim


def _frame(weldmap: WeldMap, name: str) -> np.ndarray:
    """(3, 3) the axes of a part's deviation frame in M: a box's own, a polyhedron's principal frame."""
    part = weldmap.part(name)
    if part.is_box:
        return np.asarray(part.box.X_AB[:3, :3])
    assert isinstance(part.body, Polyhedron)
    return np.asarray(principal_frame(part.body)[0][:3, :3])


def _member_deviation(rng: np.random.Generator, b: Body, design: Design) -> tuple[np.ndarray, np.ndarray, float]:
    """(size change along the member's own axes (3,) [mm], offset in M (3,) [mm], turn about the vertical [deg])."""
    R_m = rot_z(b.rpy_deg[2])  # the member's own axes in M (x along its length, z up)
    dims = np.array(b.size_mm)
    size, offset, yaw = np.zeros(3), np.zeros(3), 0.0
    if b.kind in ("tube", "pipe", "rhs", "brace") or b.name in design.held:
        size = np.zeros(3)
    else:
        size = rng.uniform(-1, 1, 3) * np.where(dims == dims.max(), TOL_LENGTH, TOL_SECTION) * dims
        if b.name == "BASE" or b.kind == "flat":
            size[2] = -abs(size[2])  # thinner only: it never grows into what lies on it
    if b.name in design.held and b.kind in ("plate", "box"):  # its faces stay: only its height changes
        size[2] = rng.uniform(-1, 1) * (TOL_LENGTH if dims[2] == dims.max() else TOL_SECTION) * dims[2]
    move = min(TOL_LOCATION * dims.max(), MOVE_MM)
    if b.kind == "brace":  # slides along the faces it meets
        slide = math.radians(b.extra["slide_deg"])
        offset = np.array([math.cos(slide), math.sin(slide), 0.0]) * rng.uniform(-0.5, 0.5)
    elif b.name in {m for m, _ in design.ending}:  # slides sideways; its end stays on the face it meets
        offset = R_m[:, 1] * rng.uniform(-0.5, 0.5) + R_m[:, 0] * size[0] / 2
    elif b.name not in design.held:
        ang = rng.uniform(0, 2 * math.pi)
        offset = np.array([math.cos(ang), math.sin(ang), 0.0]) * rng.uniform(
            0, min(move, 1.0) if b.kind in ("tube", "pipe") else move
        )
        yaw = 0.0 if b.kind in ("tube", "pipe") else rng.uniform(-YAW_DEG, YAW_DEG)
    if b.name != "BASE":
        offset[2] += size[2] / 2  # the foot stays on what it stands on
    return size, offset, yaw


def deviations(rng: np.random.Generator, design: Design, weldmap: WeldMap) -> dict[str, Any]:
    """Each part as built minus drawn, within the tolerances, in its deviation frame (a box's own, a polyhedron's
    principal frame). Boxes change size: the longest edge by up to 5 %, the others 1 %, a part's foot staying on
    what it stands on. Members move by up to 1 % of their length (at most 2 mm; tubes 1 mm) and turn by up to 0.3
    deg about the vertical. A part another's end rests on (``design.held``) only changes height; a brace or a plate
    ending on another part only slides sideways (0.5 mm), the plate's end staying where it is; RHS, tubes and pipes
    only move."""
    out: dict[str, Any] = {}
    for b in design.bodies:
        if b.kind == "fixture":
            continue
        size_m, offset_M, yaw = _member_deviation(rng, b, design)
        R_m, R_P = rot_z(b.rpy_deg[2]), _frame(weldmap, b.name)
        entry: dict[str, Any] = {}
        if np.any(size_m != 0):
            match = np.argmax(np.abs(R_P.T @ R_m), axis=1)  # the member axis along each frame axis
            entry["size_mm"] = [r6(round(size_m[j], 4)) for j in match]
        if np.any(offset_M != 0):
            entry["offset_mm"] = [r6(round(v, 4)) for v in R_P.T @ offset_M]
        if yaw:
            entry["rpy_deg"] = [r6(round(math.degrees(v), 4)) for v in matrix_to_rpy(R_P.T @ rot_z(yaw) @ R_P)]
        if entry:
            out[b.name] = entry
    return out
