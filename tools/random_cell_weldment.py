"""A random weldment (``kind = "random"`` of ``tools/random_cells.py``) drawn from the caller's generator [mm, frame
M, z = 0 on the table].

A base plate lying on the table with 2-4 members on its top, each across a drawn gap of 0-2 mm: a plate standing on
its edge (fillets on both sides), a box post or an RHS with corner radii (a fillet on each side, an RHS's on its
flats), a flat bar lying flat (lap fillets all round), or a braced pair (two parallel plates with a flat bar lying
between them at 20-70 degrees, its ends mitred onto their faces: ``tools/random_cell_frames.py``). A standing plate
or post may carry a mitred brace (a flat bar from the base up to its face at 20-70 degrees). 1-2 round tubes or
pipes stand among them (MESH or 3DFACE; half of them with a red CIRCLE at the foot: a curved seam the cell
locates). A post, tube or pipe may have a plate standing against it, its end flat on the post's face or a
facet of the tube (its fillets on the base end at that wall; on a post also the two vertical fillets of its end).
0-2 stop blocks on a fixture layer sit near a seam. Members keep 50 mm apart (room for the torch) and inside the
plate's edge beyond its build deviation.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from random_cell_build import TOL_LENGTH
from random_cell_frames import braced_pair
from random_cell_layouts import Design
from random_cell_members import Member, brace, ending_plate, rhs, round_tube, standing
from random_cell_parts import Body, Circle, Seam, box_body, prism, rectangle, rot_z, vec

CLEAR_MM = 50.0  # between members' footprints
EDGE_MM = 20.0  # members inside the base plate's edge, beyond its build deviation
RHS_SIZES = ((40, 40), (50, 30), (60, 40), (60, 60), (80, 40), (80, 80), (100, 50))  # [mm]


Capsule = tuple[float, float, float, float, float]  # a footprint: a segment (x0, y0, x1, y1) and a radius [mm]


def _gap(c: Capsule, d: Capsule) -> float:
    """The clearance [mm] between two capsules (negative: they overlap)."""
    a0, a1, b0, b1 = np.array(c[:2]), np.array(c[2:4]), np.array(d[:2]), np.array(d[2:4])

    def to_seg(p: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> float:
        v = q1 - q0
        t = 0.0 if v @ v < 1e-12 else float(np.clip((p - q0) @ v / (v @ v), 0.0, 1.0))
        return float(np.linalg.norm(p - q0 - t * v))

    da, db = a1 - a0, b1 - b0
    den = da[0] * db[1] - da[1] * db[0]
    if abs(den) > 1e-12:  # crossing segments
        w = b0 - a0
        s, t = (w[0] * db[1] - w[1] * db[0]) / den, (w[0] * da[1] - w[1] * da[0]) / den
        if 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0:
            return -c[4] - d[4]
    dist = min(to_seg(a0, b0, b1), to_seg(a1, b0, b1), to_seg(b0, a0, a1), to_seg(b1, a0, a1))
    return dist - c[4] - d[4]


def _fits(c: Capsule, placed: dict[str, Capsule], L: float, W: float, clear: float = CLEAR_MM, skip: str = "") -> bool:
    """Whether a footprint lies inside the base plate (beyond its build deviation) and ``clear`` from every one
    placed but ``skip``."""
    edge = EDGE_MM + TOL_LENGTH * max(L, W) / 2 + c[4]
    for x, y in (c[:2], c[2:4]):
        if not (edge <= x <= L - edge and edge <= y <= W - edge):
            return False
    return all(_gap(c, d) >= clear for k, d in placed.items() if k != skip)


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


def _ending(rng: np.random.Generator, name: str, host: Body, t: float) -> tuple[Member | None, str]:
    """A plate standing on the base with its end flat against the host (a post's face, a tube's facet), and the
    post's face it stands against (its own fillet on the base is then not drawn: the plate's end sits on it)."""
    face = ""
    if host.kind == "box":
        a, b, h = host.size_mm
        R = rot_z(host.rpy_deg[2])
        k = int(rng.integers(4))
        n, face = R[:, k // 2] * (1.0 if k % 2 == 0 else -1.0), ("+x", "-x", "+y", "-y")[k]
        half, width, along = (a / 2, b, R[:, 1]) if k < 2 else (b / 2, a, R[:, 0])
    else:
        segments = int(host.extra["segments"])
        ang = 2 * math.pi * int(rng.integers(segments)) / segments  # facet middles at k 360/segments degrees
        n, half, along = np.array([math.cos(ang), math.sin(ang), 0.0]), host.size_mm[0] / 2, np.zeros(3)
        width, h = 2 * half * math.tan(math.pi / segments), host.size_mm[2]
    thick = float(rng.choice([8, 10, 12]))
    if h * (1 - TOL_LENGTH) - 15 < 50:
        return None, face
    size = (rng.uniform(60, 180), thick, rng.uniform(50, h * (1 - TOL_LENGTH) - 15))
    room = max(0.0, width / 2 - thick / 2 - 5)
    F = np.array([host.centre_mm[0], host.centre_mm[1], t]) + half * n + along * rng.uniform(-room, room)
    gaps = (round(float(rng.uniform(0, 2)), 1), round(float(rng.uniform(0, 1.5)), 1))
    named_host = host.name if host.kind == "box" and width >= thick + 10 else None
    return ending_plate(name, size, F, n, "BASE", t, gaps, named_host), face


def random_design(rng: np.random.Generator) -> tuple[Design, float]:
    """A random weldment (module docstring) and the yaw it is drawn at (0: the cell turns it on the table)."""
    L, W, t = rng.uniform(350, 650), rng.uniform(250, 450), float(rng.choice([8, 10, 12, 15, 20]))
    v, f = prism(rectangle(L, W), 0.0, t, np.eye(4))
    base = Body(
        "BASE", "plate", v + np.array([L / 2, W / 2, 0.0]), f, vec((L / 2, W / 2, t / 2)), (0.0, 0.0, 0.0), (L, W, t)
    )
    bodies: list[Body] = [base]
    seams: list[Seam] = []
    circles: list[Circle] = []
    placed: dict[str, Capsule] = {}
    count: dict[str, int] = {}
    held: list[str] = []
    ending: list[tuple[str, str]] = []

    def add(m: Member) -> None:
        bodies.append(m.body)
        seams.extend(m.seams)
        placed[m.body.name] = m.footprint

    def label(kind: str) -> str:
        count[kind] = count.get(kind, 0) + 1
        return f"{kind.upper()}_{count[kind]}"

    for _ in range(int(rng.integers(2, 5))):
        kind = str(rng.choice(["plate", "box", "rhs", "flat", "pair"], p=[0.25, 0.2, 0.2, 0.15, 0.2]))
        for _try in range(30):
            xy = (float(rng.uniform(0, L)), float(rng.uniform(0, W)))
            if kind == "pair":
                n1, n2 = count.get("plate", 0) + 1, count.get("brace", 0) + 1
                names = (f"PLATE_{n1}", f"PLATE_{n1 + 1}", f"BRACE_{n2}")
                pair = braced_pair(rng, names, xy, float(rng.uniform(0.0, 180.0)), t)
                if pair is None or not _fits(pair[1], placed, L, W):
                    continue
                for m in pair[0]:
                    label(m.body.kind)
                    bodies.append(m.body)
                    seams.extend(m.seams)
                placed[names[2]] = pair[1]
                held.extend(names[:2])
                break
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
                add(br)
                held.append(m.body.name)
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
            placed[body.name] = m.footprint
            if rng.random() < 0.5:
                circles.append(Circle(f"{body.name}>BASE:foot", vec((xy[0], xy[1], t)), d / 2))
            break
    for host in [b for b in bodies if b.kind in ("box", "tube", "pipe") and b.name not in held]:
        if rng.random() >= 0.5 or (host.kind != "box" and host.size_mm[0] < 50):
            continue
        name = f"PLATE_{count.get('plate', 0) + 1}"
        for _try in range(8):  # a face (facet) and length whose plate fits
            plate, face = _ending(rng, name, host, t)
            if plate is not None and _fits(plate.footprint, placed, L, W, skip=host.name):
                break
        else:
            continue
        assert plate is not None
        seams[:] = [s for s in seams if s.id != f"{host.name}>BASE:{face}"]
        label("plate")
        add(plate)
        held.append(host.name)
        ending.append((name, host.name))
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
        foot = (fx.centre_mm[0], fx.centre_mm[1], fx.centre_mm[0], fx.centre_mm[1], r)
        if _fits(foot, placed, L, W, clear=10.0):
            bodies.append(fx)
            placed[fx.name] = foot
    facts = {"base_mm_x": L, "base_mm_y": W, "base_mm_z": t}
    return Design(tuple(bodies), tuple(seams), tuple(circles), facts, tuple(held), tuple(ending)), 0.0
