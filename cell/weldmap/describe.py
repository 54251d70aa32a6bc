"""The text of ``cell map info``: units, parts and fixtures (type box or mesh, size, centre; a round body's cylinder),
seams with their joint (type T / corner / lap, dihedral), curved seams with their curve and joint, unsupported
seams."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from cell.geometry import FloatArray, matrix_to_rpy
from cell.types import ArcCurve, CurvedSeam, EllipseCurve, Part, WeldMap


def _fmt(v: FloatArray, f: str = "8.1f") -> str:
    return "(" + ", ".join(format(float(x), f) for x in v) + ")"


def _bodies(title: str, bodies: tuple[Part, ...]) -> list[str]:
    lines = [f"{title}: {len(bodies)}"]
    width = max((len(p.name) for p in bodies), default=4)
    for p in bodies:
        kind = f"{p.kind} ({p.drawn_as})" if p.drawn_as else p.kind
        if p.is_box:
            size = " x ".join(f"{s * 1000:.1f}" for s in p.box.size)
            R = p.box.X_AB[:3, :3]
        else:  # a polyhedron: the extent of its vertices along the map's axes, and its face count
            size = "extent " + " x ".join(f"{s * 1000:.1f}" for s in np.ptp(p.vertices(), axis=0))
            kind += f" {len(p.face_names())} faces"
            R = np.eye(3)
        line = f"  {p.name:<{width}}  {kind:<16} {size:>24} mm  centre {_fmt(p.center * 1000)}"
        if not np.allclose(R, np.eye(3), atol=1e-9):
            line += "  rpy " + _fmt(np.degrees(matrix_to_rpy(R)), ".2f") + " deg"
        if (c := p.cylinder) is not None:
            bore = f" bore {c.inner_radius * 2000:.1f}" if c.inner_radius > 0 else " solid"
            line += f"  round: {c.radius * 2000:.1f} mm across{bore}, {c.length * 1000:.1f} long"
            line += f", axis {_fmt(c.axis, '+.3f')}, {c.facets} facets"
        lines.append(line)
    return lines


def _curve(c: CurvedSeam) -> str:
    """One curved seam's line: kind, size, length, plane, joint."""
    k = c.curve
    if isinstance(k, ArcCurve):
        what = f"{k.kind} r {k.radius * 1000:.1f} mm, centre {_fmt(k.centre * 1000)}, normal {_fmt(k.normal, '+.3f')}"
        if not k.closed:
            what += f", {np.degrees(k.sweep_rad):.1f} deg"
    elif isinstance(k, EllipseCurve):
        a, b = float(np.linalg.norm(k.major)), float(np.linalg.norm(k.minor))
        what = f"ellipse {a * 2000:.1f} x {b * 2000:.1f} mm, centre {_fmt(k.centre * 1000)}"
        what += f", normal {_fmt(k.normal, '+.3f')}"
    else:
        what = f"curve of {len(k.points)} points within {k.chord_error_m * 1000:.3f} mm" + (
            " closed" if k.closed else ""
        )
    joint = str(c.joint) if c.joint is not None else f"no joint: {c.note}"
    return f"{c.length * 1000:8.1f} mm  {what}  {joint}  [{c.drawn}]"


def touching(weldmap: WeldMap, margin_m: float = 0.006) -> dict[str, list[str]]:
    """The parts each seam touches (its ends and middle within ``margin_m`` of the part), by seam id."""
    out = {}
    for s in weldmap.seams:
        pts = np.array([s.p_start, s.p_end, (s.p_start + s.p_end) / 2.0])
        out[s.id] = [p.name for p in weldmap.parts if bool(np.all(p.contains(pts, margin_m)))]
    return out


def describe(weldmap: WeldMap, joints: Mapping[str, str] | None = None) -> str:
    """Multi-line summary for ``cell map info``: file, units, parts and fixtures (box size and centre [mm]), seams
    [mm] with the joint of each (``joints``: seam id -> text, e.g. ``T POST_L > TOP_RAIL``; else the parts each
    seam touches), then the unsupported seams and why."""
    lines = [
        f"file:  {weldmap.source}",
        f"units: {weldmap.units} (shown in mm, frame {weldmap.frame})",
        *_bodies("parts", weldmap.parts),
    ]
    if weldmap.fixtures:
        lines += _bodies("fixtures", weldmap.fixtures)
    lines.append(f"seams: {len(weldmap.seams)}")
    width = max((len(s.id) for s in weldmap.seams), default=4)
    on = touching(weldmap) if joints is None else {}
    for s in weldmap.seams:
        note = joints.get(s.id, "no joint") if joints is not None else " + ".join(on[s.id]) or "touches no part"
        lines.append(
            f"  {s.id:<{width}}  {s.length * 1000:8.1f} mm  from {_fmt(s.p_start * 1000)}"
            f"  dir {_fmt(s.direction, '+.3f')}  {note}"
        )
    if weldmap.curved:
        loose = sum(c.joint is None for c in weldmap.curved)
        lines.append(
            f"curved seams: {len(weldmap.curved)} (a run locates each and welds it or says why not"
            + (f"; {loose} with no joint: not located)" if loose else ")")
        )
        width = max(len(c.id) for c in weldmap.curved)
        lines += [f"  {c.id:<{width}}  {_curve(c)}" for c in weldmap.curved]
    if weldmap.unsupported:
        lines.append(f"unsupported seams: {len(weldmap.unsupported)}")
        width = max(len(u.id) for u in weldmap.unsupported)
        lines += [f"  {u.id:<{width}}  {u.code}: {u.reason}" for u in weldmap.unsupported]
    return "\n".join(lines)
