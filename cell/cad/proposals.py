"""Seams proposed from a CAD's contacts: each contact a fillet with its id (``A>B:where``), its joint type and
dihedral, proposed or rejected with a reason (a fastener's, a fixture's, too short, inside a bore)."""

from __future__ import annotations

import enum
import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from cell.cad.contacts import Contact, contacts, stretch
from cell.cad.model import Body, CadModel, CurveKind, Edge, SurfaceKind
from cell.cad.roles import Role, polyhedron, roles
from cell.geometry import FloatArray

GAP_M = 0.003  # two bodies this close touch (the map reader's joints allow up to 6 mm) [m]
MIN_LENGTH_M = 0.020  # a fillet shorter than this (a plate's end, 12 mm across) is listed, not proposed [m]
BORE_M = 0.100  # a fillet inside a bore narrower than this is out of a torch's reach [m]
_AXIS_COS = math.cos(math.radians(5.0))
_COPLANAR_M = 0.003  # a face of the abutting part this close to one of the receiving part's: flush (a corner)


class Rejection(enum.StrEnum):
    """Why a contact is listed but not proposed (``None``: proposed)."""

    FASTENER = "fastener"  # on a bolt, nut or washer: bolted, not welded
    FIXTURE = "fixture"  # on a body of a fixture layer
    SHORT = "short"  # shorter than the shortest proposed seam
    BORE = "bore"  # inside a bore too narrow for the torch


class Joint(enum.StrEnum):
    T = "T"
    CORNER = "corner"
    LAP = "lap"


@dataclass(frozen=True)
class Proposal:
    """One fillet: ``abutting`` rests on ``receiving``; its geometry (a line, an arc or circle, another curve) in
    ``M`` [m]; the dihedral [rad] between the free face and the receiving face; ``rejected`` None when proposed."""

    id: str
    abutting: str
    receiving: str
    curve: Edge
    joint: Joint
    dihedral: float
    rejected: Rejection | None

    @property
    def curved(self) -> bool:
        return self.curve.kind != CurveKind.LINE


@dataclass(frozen=True)
class Proposals:
    """A CAD read and its seams proposed: every body with its role, every proposal (proposed and rejected)."""

    model: CadModel
    roles: tuple[Role, ...]
    seams: tuple[Proposal, ...]

    @property
    def proposed(self) -> tuple[Proposal, ...]:
        return tuple(s for s in self.seams if s.rejected is None)


def _where(n: FloatArray, curve: Edge) -> str:
    """A short name for where the seam runs: the free face's axis (``+y``), else ``circle``, ``arc`` or ``curve``."""
    if curve.kind == CurveKind.ARC:
        return "circle" if curve.closed else "arc"
    if curve.kind == CurveKind.CURVE:
        return "curve"
    k = int(np.argmax(np.abs(n)))
    if abs(float(n[k])) >= _AXIS_COS:
        return ("+" if n[k] > 0 else "-") + "xyz"[k]
    return "side"


def _joint(a: Body, b: Body, c: Contact) -> Joint:
    """T, corner or lap as the map reader's joint finder tells them (cell.seams.joint.joint_kind)."""
    if np.ptp(a.vertices @ c.n_rest) < np.ptp(a.vertices @ c.n_free):
        return Joint.LAP
    for fa in a.faces:
        if fa.kind != SurfaceKind.PLANE or float(fa.normal @ c.n_free) > -_AXIS_COS:
            continue
        for fb in b.faces:
            flush = abs(fb.offset - fa.offset) <= _COPLANAR_M
            if fb.kind == SurfaceKind.PLANE and float(fb.normal @ fa.normal) >= _AXIS_COS and flush:
                return Joint.CORNER
    return Joint.T


def _in_bore(a: Body, c: Contact, curve: Edge) -> bool:
    """Whether the free face is the inside of a bore narrower than BORE_M (a tube's inner wall, a hole's)."""
    if curve.kind != CurveKind.ARC:
        return False
    mid = curve.at(np.array([0.5]))[0]
    inward = float(c.n_free @ (curve.centre - mid)) > 0.0
    return inward and 2.0 * curve.radius < BORE_M


def propose(model: CadModel, gap_m: float = GAP_M, min_length_m: float = MIN_LENGTH_M) -> Proposals:
    """Every fillet of the CAD's contacts, proposed or rejected with its reason, in a stable order."""
    bodies = model.bodies
    polys = [polyhedron(b) for b in bodies]
    role = roles(bodies, polys, gap_m)
    raw: list[tuple[str, Contact, Edge]] = []
    for c in contacts(bodies, polys, gap_m):
        curve = stretch(bodies[c.a].edges[c.edge], c.t0, c.t1)
        raw.append((f"{bodies[c.a].name}>{bodies[c.b].name}:{_where(c.n_free, curve)}", c, curve))
    count = Counter(name for name, _, _ in raw)
    index: Counter[str] = Counter()
    seams = []
    for name, c, curve in raw:
        index[name] += 1
        a, b = bodies[c.a], bodies[c.b]
        why: Rejection | None = None
        if Role.FASTENER in (role[c.a], role[c.b]):
            why = Rejection.FASTENER
        elif Role.FIXTURE in (role[c.a], role[c.b]):
            why = Rejection.FIXTURE
        elif _in_bore(a, c, curve):
            why = Rejection.BORE
        elif curve.length < min_length_m:
            why = Rejection.SHORT
        seam_id = f"{name}.{index[name]}" if count[name] > 1 else name
        seams.append(Proposal(seam_id, a.name, b.name, curve, _joint(a, b, c), c.dihedral, why))
    return Proposals(model, tuple(role), tuple(seams))


def summary_rows(found: Proposals) -> list[tuple[str, str, str, str, str, str]]:
    """One row per seam for the command line: id, shape, length [mm], joint, dihedral [deg], status."""
    rows = []
    for s in found.seams:
        shape = s.curve.kind.value if not s.curve.closed else "circle"
        status = "proposed" + (" (curved)" if s.curved else "") if s.rejected is None else f"rejected: {s.rejected}"
        rows.append(
            (s.id, shape, f"{s.curve.length * 1000:.1f}", s.joint.value, f"{math.degrees(s.dihedral):.0f}", status)
        )
    return rows


def names_unique(bodies: Sequence[Body]) -> list[str]:
    """The bodies' names made unique (``_1``, ``_2`` for repeats), as the map reader would make them."""
    count = Counter(b.name for b in bodies)
    index: Counter[str] = Counter()
    out = []
    for b in bodies:
        index[b.name] += 1
        out.append(f"{b.name}_{index[b.name]}" if count[b.name] > 1 else b.name)
    return out
