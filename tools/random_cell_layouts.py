"""The named layouts of ``tools/random_cells.py``: the parts of the three cases the random cells must not get wrong
(a post among pipes, a web ending against a tube, a ladder with a mitred brace) [mm, frame M, z = 0 on the table].

Each returns its bodies, seams and the figures its truth records; the cameras and the rest of the scenario come
from ``tools/random_cell_scene.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from make_maps import junction_seams
from random_cell_members import round_tube, standing
from random_cell_parts import Body, Circle, Seam, prism, vec


@dataclass(frozen=True)
class Design:
    """A weldment: its bodies (parts and fixtures), seams, curved seams, what its truth records, and which parts
    the build deviations must keep in place (``held``, ``ending``)."""

    bodies: tuple[Body, ...]
    seams: tuple[Seam, ...]
    circles: tuple[Circle, ...] = ()
    facts: dict[str, float] = field(default_factory=dict)
    held: tuple[str, ...] = ()  # parts another member's end rests against: they must not move as built
    ending: tuple[tuple[str, str], ...] = ()  # (member, part): the member's -x end rests against the part's face


def _box(name: str, kind: str, lo: tuple[float, float, float], hi: tuple[float, float, float]) -> Body:
    size = tuple(h - low for low, h in zip(lo, hi, strict=True))
    centre = tuple((low + h) / 2 for low, h in zip(lo, hi, strict=True))
    v, f = prism([(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])], lo[2], hi[2], np.eye(4))
    return Body(name, kind, v, f, vec(centre), (0.0, 0.0, 0.0), (size[0], size[1], size[2]))


def post_pipes() -> Design:
    """A 400 x 300 x 12 plate, a 40 x 40 x 150 square post standing on its middle (four fillets, gap 0) and two round
    pipes standing beside it (60.3 x 3.9 and 88.9 x 5.5, drawn as MESH with 32 facets; not welded)."""
    t = 12.0
    plate = _box("PLATE", "plate", (0.0, 0.0, 0.0), (400.0, 300.0, t))
    post = standing("POST", "box", (40.0, 40.0, 150.0), (200.0, 150.0), 0.0, "PLATE", t, 0.0, ("+x", "-x", "+y", "-y"))
    pipe1 = round_tube("PIPE_1", "pipe", 60.3, 3.9, 220.0, (110.0, 190.0), t, 32)
    pipe2 = round_tube("PIPE_2", "pipe", 88.9, 5.5, 260.0, (300.0, 105.0), t, 32)
    return Design((plate, post.body, pipe1.body, pipe2.body), post.seams)


def web_tube() -> Design:
    """A 250 x 400 x 10 plate, a round tube (100 x 2.6, 200 high, 24 facets) standing on it, and a 10 mm web (170 long
    along y, 120 high) standing on the plate whose end lies flat against the tube's facet facing it: the web's two
    fillets on the plate end at the tube's wall. Three MESH bodies; cell init's cameras (either side along x) see
    the web's sides."""
    t, r = 10.0, 50.0
    tube = round_tube("TUBE", "tube", 2 * r, 2.6, 200.0, (125.0, 290.0), t, 24)
    y_end = 290.0 - r  # the tube's facet facing -y
    web_len = 170.0
    web = standing(
        "WEB", "plate", (web_len, 10.0, 120.0), (125.0, y_end - web_len / 2), 90.0, "PLATE", t, 0.0, ("+y", "-y")
    )
    plate = _box("PLATE", "plate", (0.0, 0.0, 0.0), (250.0, 400.0, t))
    return Design((plate, web.body, tube.body), web.seams, facts={"tube_wall_y_mm": y_end, "tube_radius_mm": r})


def _dihedral(n_a: np.ndarray, n_b: np.ndarray) -> float:
    """The angle [deg] inside the fillet between two faces of outward normals n_a, n_b."""
    return 180.0 - math.degrees(math.acos(max(-1.0, min(1.0, float(np.dot(n_a, n_b))))))


def mitred_ladder(angle_deg: float = 44.0) -> Design:
    """Two 80 x 80 rails along x, three 40 x 40 rungs between them (1 mm gaps), and a 30 x 20 flat bar lying on the
    table between the first two rungs, its axis at ``angle_deg`` to the rungs, both ends mitred to lie flat on the
    rung faces across 1 mm. Seams: every rung's four per rail end (as fence1's) and, at each brace end on the rung
    face, its top and bottom fillets and those of its cheeks where the angle allows (35-145 degrees)."""
    if not 20.0 <= angle_deg <= 70.0:
        raise ValueError(f"the brace's angle to the rungs must be 20-70 deg, got {angle_deg}")
    a = math.radians(angle_deg)
    rail, rung, gap, clear, w, h = 80.0, 40.0, 1.0, 160.0, 30.0, 20.0
    extent = (clear - 2 * gap) / math.tan(a) + w / math.sin(a)  # the brace's run along y
    span = max(400.0, 10.0 * math.ceil((extent + 120.0) / 10.0))  # rung length between the rails' faces
    pitch, first = clear + rung, 80.0
    length = 2 * first + 2 * pitch + rung
    parts = {
        "RAIL_A": ((0.0, 0.0, 0.0), (length, rail, rail)),
        "RAIL_B": ((0.0, rail + span, 0.0), (length, 2 * rail + span, rail)),
    }
    for i in range(3):
        x0 = first + i * pitch
        parts[f"RUNG_{i + 1}"] = ((x0, rail + gap, 0.0), (x0 + rung, rail + span - gap, rung))
    seams = [
        Seam(sid, vec(p0), vec(p1), sid.split(">")[0], sid.split(">")[1].split(":")[0], 90.0)
        for i in range(3)
        for r in ("RAIL_A", "RAIL_B")
        for sid, p0, p1 in junction_seams(parts, f"RUNG_{i + 1}", r)
    ]
    x1, x2 = parts["RUNG_1"][1][0], parts["RUNG_2"][0][0]  # the rung faces the brace meets
    xl, xr = x1 + gap, x2 - gap
    cx, cy = (x1 + x2) / 2, rail + span / 2
    m = np.array([math.cos(a), -math.sin(a), 0.0])  # across the brace, in the table's plane (its lower cheek's normal)

    def y_at(x: float, side: float) -> float:
        return cy + ((x - cx) * math.cos(a) - side * w / 2) / math.sin(a)

    outline = [(xl, y_at(xl, 1)), (xr, y_at(xr, 1)), (xr, y_at(xr, -1)), (xl, y_at(xl, -1))]
    v, f = prism(outline, 0.0, h, np.eye(4))
    brace_len = math.hypot(xr - xl, y_at(xr, 0) - y_at(xl, 0))
    extra = {"angle_to_rungs_deg": angle_deg}
    centre = vec((cx, cy, h / 2))
    brace = Body("BRACE", "brace", v, f, centre, (0.0, 0.0, 90.0 - angle_deg), (brace_len, w, h), extra=extra)
    for rung_name, x, n_b in (("RUNG_1", x1, np.array([1.0, 0.0, 0.0])), ("RUNG_2", x2, np.array([-1.0, 0.0, 0.0]))):
        xe = xl if rung_name == "RUNG_1" else xr
        lo, hi = y_at(xe, 1), y_at(xe, -1)
        for face, p0, p1, n_a in (
            ("top", (x, lo, h), (x, hi, h), np.array([0.0, 0.0, 1.0])),
            ("bottom", (x, lo, 0.0), (x, hi, 0.0), np.array([0.0, 0.0, -1.0])),
            ("lower", (x, y_at(x, 1), 0.0), (x, y_at(x, 1), h), m),  # a cheek's plane meets the face at y_at(x)
            ("upper", (x, y_at(x, -1), 0.0), (x, y_at(x, -1), h), -m),
        ):
            deg = _dihedral(n_a, n_b)
            if 35.0 <= deg <= 145.0:
                seams.append(Seam(f"BRACE>{rung_name}:{face}", vec(p0), vec(p1), "BRACE", rung_name, deg))
    bodies = [_box(name, "box", lo_, hi_) for name, (lo_, hi_) in parts.items()] + [brace]
    facts = {"brace_angle_to_rungs_deg": angle_deg, "brace_width_mm": w, "gap_mm": gap}
    return Design(tuple(bodies), tuple(seams), facts=facts)


NAMED = {"post_pipes": post_pipes, "web_tube": web_tube, "mitred_ladder": mitred_ladder}


def named(kind: str) -> tuple[Design, float]:
    """The design of a named layout ``name[:parameter]`` and the yaw [deg] it is placed at on the table (the
    ``web_tube`` parameter turns it; ``mitred_ladder``'s is the brace's angle)."""
    name, _, param = kind.partition(":")
    if name not in NAMED:
        raise ValueError(
            f"unknown kind {kind!r}; valid: random, {', '.join(NAMED)} (mitred_ladder:ANGLE, web_tube:YAW)"
        )
    if name == "mitred_ladder":
        return mitred_ladder(float(param) if param else 44.0), 0.0
    if param and name != "web_tube":
        raise ValueError(f"{name} takes no parameter, got {kind!r}")
    design = post_pipes() if name == "post_pipes" else web_tube()
    return design, float(param) if param else 0.0


__all__ = ["NAMED", "Design", "mitred_ladder", "named", "post_pipes", "web_tube"]
