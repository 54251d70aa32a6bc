"""A random weldment (``kind = "random"`` of ``tools/random_cells.py``) and what the simulation does to it: the
realism options and the build deviations, all drawn from the caller's generator [mm, frame M, z = 0 on the table].

The weldment is a base plate lying on the table with 2-4 members on its top, each across a drawn gap of 0-2 mm: a
plate standing on its edge (fillets on both sides), a box post or an RHS with corner radii (a fillet on each side,
an RHS's on its flats), a flat bar lying flat (lap fillets all round); a standing plate or post may carry a mitred
brace (a flat bar from the base up to its face at 20-70 degrees); 1-2 round tubes or pipes stand among them (MESH or
3DFACE; half of them with a red CIRCLE at the foot, which the cell lists as unsupported); 0-2 stops on a fixture
layer sit near a seam. Members keep 50 mm apart (room for the torch) and inside the plate's edge.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
from random_cell_layouts import Design
from random_cell_members import Member, brace, rhs, round_tube, standing
from random_cell_parts import Body, Circle, Seam, box_body, prism, rectangle, rot_z, vec
from random_cell_scene import Placement, r6

from cell.asbuilt_shapes import principal_frame
from cell.geometry import matrix_to_rpy
from cell.types import Polyhedron, WeldMap

CLEAR_MM = 50.0  # between members' footprints
EDGE_MM = 20.0  # members inside the base plate's edge, beyond its build deviation
RHS_SIZES = ((40, 40), (50, 30), (60, 40), (60, 60), (80, 40), (80, 80), (100, 50))  # [mm]
# The paper's industrial tolerances (docs/trust.md): width and height 1 %, length 5 %, location 1 %.
TOL_SECTION, TOL_LENGTH, TOL_LOCATION = 0.01, 0.05, 0.01
YAW_DEG = 0.3  # a member's turn about the vertical as built [deg]


def _fits(
    c: tuple[float, float, float], placed: list[tuple[float, float, float]], L: float, W: float, clear: float = CLEAR_MM
) -> bool:
    """Whether a footprint circle (x, y, r) [mm] lies inside the base plate (beyond its build deviation) and
    ``clear`` from every one placed."""
    x, y, r = c
    edge = EDGE_MM + TOL_LENGTH * max(L, W) / 2
    if not (edge + r <= x <= L - edge - r and edge + r <= y <= W - edge - r):
        return False
    return all(math.hypot(x - px, y - py) >= r + pr + clear for px, py, pr in placed)


def _member(rng: np.random.Generator, kind: str, name: str, xy: tuple[float, float], t: float) -> Member:
    yaw, gap = float(rng.uniform(0.0, 180.0)), round(float(rng.uniform(0.0, 2.0)), 1)
    if kind == "plate":
        size = (rng.uniform(80, 220), float(rng.choice([8, 10, 12, 15])), rng.uniform(60, 180))
        return standing(name, "plate", size, xy, yaw, "BASE", t, gap, ("+y", "-y"))
    if kind == "box":
        size = (rng.uniform(30, 80), rng.uniform(30, 80), rng.uniform(60, 200))
        return standing(name, "box", size, xy, yaw, "BASE", t, gap, ("+x", "-x", "+y", "-y"))
    if kind == "flat":
        size = (rng.uniform(80, 220), rng.uniform(30, 80), float(rng.choice([5, 6, 8, 10, 12])))
        return standing(name, "flat", size, xy, yaw, "BASE", t, gap, ("+x", "-x", "+y", "-y"))
    a, b = RHS_SIZES[int(rng.integers(len(RHS_SIZES)))]
    walls = [w for w in (3.0, 4.0, 5.0) if min(a, b) - 4 * w >= 15.0]  # every flat (a - 4 wall) 15 mm or more
    return rhs(
        name, (float(a), float(b), rng.uniform(80, 220)), walls[int(rng.integers(len(walls)))], xy, yaw, "BASE", t, gap
    )


def _brace(rng: np.random.Generator, name: str, host: Member, t: float) -> Member | None:
    """A mitred brace on one of the host's faces (a standing plate's sides, any of a post's)."""
    b = host.body
    a_len, thick_h, h = b.size_mm
    R = rot_z(b.rpy_deg[2])
    faces = [(R[:, 1], thick_h / 2, R[:, 0], a_len), (-R[:, 1], thick_h / 2, R[:, 0], a_len)]
    if b.kind == "box":
        faces += [(R[:, 0], a_len / 2, R[:, 1], thick_h), (-R[:, 0], a_len / 2, R[:, 1], thick_h)]
    n, half, along, face_len = faces[int(rng.integers(len(faces)))]
    theta, width, thick = rng.uniform(20, 70), rng.uniform(25, 50), float(rng.choice([6, 8, 10, 12]))
    room = face_len * (1 - TOL_LENGTH) / 2 - width / 2 - 5
    lo_rise = 45 + thick / math.cos(math.radians(theta))  # the host's own fillet passes under the brace
    hi_rise = h * (1 - TOL_LENGTH) - 10
    if room < 0 or hi_rise < lo_rise:
        return None
    F = np.array([b.centre_mm[0], b.centre_mm[1], t]) + half * n + along * rng.uniform(-room, room)
    gaps = (round(float(rng.uniform(0, 2)), 1), round(float(rng.uniform(0, 2)), 1))
    return brace(name, b.name, "BASE", F, n, t, theta, width, thick, rng.uniform(lo_rise, hi_rise), gaps)


def _fixture(rng: np.random.Generator, name: str, seam: Seam, away: np.ndarray, t: float) -> Body:
    """A stop block on the base beside a seam, 35-60 mm from it on the fillet's side."""
    p0, p1 = np.array(seam.p0), np.array(seam.p1)
    size = (rng.uniform(30, 50), rng.uniform(25, 40), rng.uniform(20, 40))
    centre = (p0 + p1) / 2 + away * (rng.uniform(35, 60) + size[1] / 2)
    yaw = math.degrees(math.atan2(p1[1] - p0[1], p1[0] - p0[0]))
    return box_body(name, "fixture", size, (centre[0], centre[1], t + size[2] / 2), yaw)


def random_design(rng: np.random.Generator) -> tuple[Design, float]:
    """A random weldment (module docstring) and the yaw it is drawn at (0: the cell turns it on the table)."""
    L, W, t = rng.uniform(350, 650), rng.uniform(250, 450), float(rng.choice([8, 10, 12, 15, 20]))
    v, f = prism(rectangle(L, W), 0.0, t, np.eye(4))
    base = Body(
        "BASE", "plate", v + np.array([L / 2, W / 2, 0.0]), f, vec((L / 2, W / 2, t / 2)), (0.0, 0.0, 0.0), (L, W, t)
    )
    bodies, seams, circles = [base], [], []
    placed: list[tuple[float, float, float]] = []
    count: dict[str, int] = {}

    def add(m: Member) -> None:
        bodies.append(m.body)
        seams.extend(m.seams)
        placed.append(m.footprint)

    def label(kind: str) -> str:
        count[kind] = count.get(kind, 0) + 1
        return f"{kind.upper()}_{count[kind]}"

    for _ in range(int(rng.integers(2, 5))):
        kind = str(rng.choice(["plate", "box", "rhs", "flat"], p=[0.3, 0.25, 0.25, 0.2]))
        for _try in range(30):
            xy = (float(rng.uniform(0, L)), float(rng.uniform(0, W)))
            m = _member(rng, kind, f"{kind.upper()}_{count.get(kind, 0) + 1}", xy, t)
            if not _fits(m.footprint, placed, L, W):
                continue
            br = (
                _brace(rng, f"BRACE_{count.get('brace', 0) + 1}", m, t)
                if kind in ("plate", "box") and rng.random() < 0.5
                else None
            )
            if br is not None and not _fits(br.footprint, placed, L, W):
                br = None
            label(kind)
            add(m)
            if br is not None:
                label("brace")
                bodies.append(br.body)
                seams.extend(br.seams)
                placed.append(br.footprint)
            break
    for _ in range(int(rng.integers(1, 3))):
        pipe = bool(rng.random() < 0.5)
        d = rng.uniform(60, 170) if pipe else rng.uniform(25, 60)
        wall = rng.uniform(3, 8) if pipe else float(rng.choice([2, 3, 4]))
        for _try in range(30):
            xy = (float(rng.uniform(0, L)), float(rng.uniform(0, W)))
            kind = "pipe" if pipe else "tube"
            m = round_tube(
                f"{kind.upper()}_{count.get(kind, 0) + 1}",
                kind,
                d,
                wall,
                rng.uniform(80, 300),
                xy,
                t,
                int(rng.choice([16, 24, 32])),
            )
            if not _fits(m.footprint, placed, L, W):
                continue
            label(kind)
            body = m.body if rng.random() < 0.5 else replace(m.body, drawn_as="3dface")
            bodies.append(body)
            placed.append(m.footprint)
            if rng.random() < 0.5:
                circles.append(Circle(f"{body.name}>BASE:foot", vec((xy[0], xy[1], t)), d / 2))
            break
    on_base = [s for s in seams if s.receiving == "BASE"]
    for k in range(int(rng.integers(0, 3)) if on_base else 0):
        s = on_base[int(rng.integers(len(on_base)))]
        owner = next(b for b in bodies if b.name == s.abutting)
        mid = (np.array(s.p0) + np.array(s.p1)) / 2
        away = mid - np.array(owner.centre_mm)
        away[2] = 0.0
        d = np.array(s.p1) - np.array(s.p0)
        d[2] = 0.0
        away -= d * (away @ d) / max(float(d @ d), 1e-9)
        if np.linalg.norm(away) < 1e-6:
            continue
        fx = _fixture(rng, f"FIXTURE_{k + 1}", s, away / np.linalg.norm(away), t)
        r = math.hypot(fx.size_mm[0], fx.size_mm[1]) / 2
        if _fits((fx.centre_mm[0], fx.centre_mm[1], r), placed, L, W, clear=10.0):
            bodies.append(fx)
            placed.append((fx.centre_mm[0], fx.centre_mm[1], r))
    return Design(
        tuple(bodies), tuple(seams), tuple(circles), facts={"base_mm_x": L, "base_mm_y": W, "base_mm_z": t}
    ), 0.0


def realism(rng: np.random.Generator, design: Design, weldmap: WeldMap, placement: Placement) -> dict[str, Any]:
    """The ``simulation`` keys of a random cell but its deviations: noise realistic (4 in 5) or none, the operator's
    placement error (up to 5 mm, 0.5 deg), and each of the realism options half the time (gaps varying to 0.5-2 mm,
    tacks at the seam ends, specular dropout on shiny faces)."""
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


def deviations(rng: np.random.Generator, design: Design, weldmap: WeldMap) -> dict[str, Any]:
    """Each part as built minus drawn, within the tolerances (module constants), in its deviation frame: boxes
    change size (the longest edge by up to 5 %, the others 1 %; a part's foot stays on what it stands on), members
    move by up to 1 % of their length and turn by up to 0.3 deg about the vertical; a brace only slides along its
    width, a brace's host only changes length; RHS, tubes and pipes only move."""
    hosts = {s.receiving for s in design.seams if s.abutting.startswith("BRACE") and s.receiving != "BASE"}
    out: dict[str, Any] = {}
    for b in design.bodies:
        if b.kind == "fixture":
            continue
        R_m = rot_z(b.rpy_deg[2])  # the member's own axes in M (x along its length, z up)
        dims = np.array(b.size_mm)
        size_m, offset_M, yaw = np.zeros(3), np.zeros(3), 0.0
        if b.kind in ("plate", "box", "flat") and b.name not in hosts:
            tol = np.where(dims == dims.max(), TOL_LENGTH, TOL_SECTION)
            size_m = rng.uniform(-1, 1, 3) * tol * dims
            if b.name == "BASE" or b.kind == "flat":
                size_m[2] = -abs(size_m[2])  # thinner only: it never grows into what lies on it
        elif b.name in hosts:
            size_m[0] = rng.uniform(-1, 1) * TOL_LENGTH * dims[0]
        if b.kind == "brace":
            offset_M = R_m[:, 1] * rng.uniform(-0.5, 0.5)
        elif b.name not in hosts:
            ang = rng.uniform(0, 2 * math.pi)
            reach = min(TOL_LOCATION * dims.max(), 1.0 if b.kind in ("tube", "pipe") else 2.0)
            offset_M = np.array([math.cos(ang), math.sin(ang), 0.0]) * rng.uniform(0, reach)
            yaw = 0.0 if b.kind in ("tube", "pipe") else rng.uniform(-YAW_DEG, YAW_DEG)
        offset_M = offset_M + np.array([0.0, 0.0, size_m[2] / 2]) * (b.name != "BASE")  # the foot stays
        R_P = _frame(weldmap, b.name)
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
