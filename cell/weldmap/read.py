"""DXF welding map -> :class:`~cell.types.WeldMap`: content first, then units, then geometry, then roles."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
from ezdxf.document import Drawing

from cell.errors import MapError
from cell.geometry import FloatArray
from cell.types import Box, CurvedSeam, MapSeam, Part, Polyhedron, WeldMap
from cell.types.map import Unsupported, UnsupportedSeam
from cell.weldmap._load import MALFORMED, ezdxf_to_log, kind_of, load, log
from cell.weldmap._walk import Found, RawBody, RawSeam, Reader
from cell.weldmap.boxfit import BOX_TOL, bounding_box, fit_box, open_edges, zero_area_faces
from cell.weldmap.curved_joints import curved_joint
from cell.weldmap.cylinders import recognise_cylinder
from cell.weldmap.polyfit import fit_polyhedron
from cell.weldmap.roles import LayerPatterns, LayerRoles, body_role
from cell.weldmap.units import METRES_PER_UNIT, extent_warning, resolve_units

MIN_SEAM_LENGTH = 1e-6  # [m]
FLAT_REL = 1e-6  # a drawing whose z extent is below this fraction of its extent is flat
MAX_COORD_M = 1e4  # 10 km: no welding cell is larger; a coordinate beyond is a broken file
TOUCH_M = 0.006  # a seam point this close to a body [m] touches it (the joint finder's largest gap)
WHAT = (
    "a welding map holds red 3D LINEs or polylines (the seams) and 3D bodies "
    "(3DSOLID, MESH, POLYFACE or 3DFACE: the parts)"
)


def _plural(n: int, word: str) -> str:
    return f"{n:,} {word}" + ("" if n == 1 else "s")


def summary(found: Found) -> str:
    """What a drawing holds, for a message: e.g. ``10,052 LINEs, none red; no 3D bodies``."""
    k = found.kinds
    red = "none" if found.red == 0 else f"{found.red:,}"
    text = f"{_plural(k['LINE'], 'LINE')}, {red} red"
    others = [(n, c) for n, c in k.most_common() if n not in ("LINE", "INSERT", "3DSOLID", "MESH", "3DFACE")]
    if others:
        text += ", also " + ", ".join(f"{c:,} {n}" for n, c in others[:3])
    bodies = len(found.bodies)
    return text + ("; no 3D bodies" if bodies == 0 else f"; {_plural(bodies, '3D body')}".replace("bodys", "bodies"))


def _points(found: Found) -> FloatArray:
    pts = [p for s in found.seams for p in (s.a, s.b)]
    pts += [p for c in found.curves for p in _curve_probe(c.curve)]
    pts += [v for b in found.bodies if b.mesh is not None for v in b.mesh[0]]
    return np.array(pts, dtype=float).reshape(-1, 3)


def _curve_probe(curve: object) -> FloatArray:
    """A curve's points for the extent checks: a sampled curve's own, an arc's or ellipse's every 10 degrees."""
    from cell.types import SampledCurve

    if isinstance(curve, SampledCurve):
        return np.asarray(curve.points)
    t = np.linspace(0.0, curve.sweep_rad, 37) + getattr(curve, "start_rad", 0.0)  # type: ignore[attr-defined]
    return np.asarray(curve.at(t))  # type: ignore[attr-defined]


def _check_content(found: Found, doc: Drawing, src: str) -> None:
    if len(doc.modelspace()) == 0:
        raise MapError(f"{src}: the drawing is empty (truncated or blank?); {WHAT}")
    if not found.seams and not found.curves and not found.bodies:
        raise MapError(f"{src}: not a welding map: {summary(found)}; {WHAT}")
    _check_extent(found, None, src)
    P = _points(found)
    if len(P) and float(np.ptp(P[:, 2])) <= FLAT_REL * float(np.ptp(P, axis=0).max()):
        raise MapError(f"{src}: the drawing is flat (all z equal), a 2D drawing: {summary(found)}; {WHAT} in 3D")
    if not found.seams and not found.curves:
        raise MapError(f"{src}: no red weld seams ({summary(found)}); {WHAT}")
    if not found.bodies:
        raise MapError(f"{src}: no parts ({summary(found)}); {WHAT}")


def _check_extent(found: Found, scale: float | None, src: str) -> None:
    """Refuse a coordinate beyond 10 km (``scale`` None: before the units are known, beyond 10 km in any units)."""
    far = [(s.where, max(np.abs(s.a).max(), np.abs(s.b).max())) for s in found.seams]
    far += [(c.where, np.abs(_curve_probe(c.curve)).max()) for c in found.curves]
    far += [(b.where, np.abs(b.mesh[0]).max()) for b in found.bodies if b.mesh is not None]
    least = min(METRES_PER_UNIT.values())
    for where, c in far:
        if scale is None and c * least > MAX_COORD_M:
            raise MapError(
                f"{src}: {where} has a coordinate {c:.3g} from the origin, beyond 10 km in any units; "
                "a welding map is a few metres across (a broken number?)"
            )
        if scale is not None and c * scale > MAX_COORD_M:
            raise MapError(
                f"{src}: {where} has a coordinate {c * scale:.3g} m from the origin, beyond 10 km; "
                "a welding map is a few metres across (a broken number? other units?)"
            )


def _seams(found: Found, scale: float, src: str) -> list[tuple[MapSeam, RawSeam]]:
    seams = []
    for raw in found.seams:
        s = MapSeam(raw.id, raw.a * scale, raw.b * scale)
        if s.length < MIN_SEAM_LENGTH:
            raise MapError(f"{src}: seam {raw.id} has zero length ({raw.where}); a seam needs two distinct end points")
        seams.append((s, raw))
    ids = Counter([s.id for s, _ in seams] + [c.id for c in found.curves])
    dup = [i for i, n in ids.items() if n > 1]
    if dup:
        raise MapError(f"{src}: seam id {dup[0]} appears {ids[dup[0]]} times; seam ids must be unique")
    return seams


def _touching(boxes: list[Part], pts: FloatArray) -> np.ndarray:
    """(n_seams, n_boxes) whether each seam's points (n_seams, k, 3) all lie within TOUCH_M of each box."""
    out = np.zeros((len(pts), len(boxes)), dtype=bool)
    for j, part in enumerate(boxes):
        if not part.is_box:
            out[:, j] = part.contains(pts.reshape(-1, 3), TOUCH_M).reshape(pts.shape[:2]).all(axis=1)
            continue
        X, half = part.box.X_AB, part.box.size / 2.0 + TOUCH_M
        p_B = (pts - X[:3, 3]) @ X[:3, :3]  # into the box frame
        out[:, j] = np.all(np.abs(p_B) <= half, axis=(1, 2))
    return out


def _near(vertices: FloatArray | None, pts: FloatArray) -> bool:
    if vertices is None:
        return False
    lo, hi = vertices.min(axis=0) - TOUCH_M, vertices.max(axis=0) + TOUCH_M
    return bool(np.any(np.all((pts >= lo) & (pts <= hi), axis=1)))


def _named(found: list[tuple[RawBody, Box | Polyhedron]]) -> list[Part]:
    count = Counter(b.name for b, _ in found)
    index: Counter[str] = Counter()
    parts = []
    for b, box in found:
        index[b.name] += 1
        name = f"{b.name}_{index[b.name]}" if count[b.name] > 1 else b.name
        parts.append(Part(name, box, b.drawn_as, recognise_cylinder(box) if isinstance(box, Polyhedron) else None))
    return parts


def _bodies(
    found: Found, spec: LayerPatterns, scale: float, src: str, warnings: list[str]
) -> tuple[list[Part], list[Part], list[tuple[RawBody, FloatArray | None, str]]]:
    parts: list[tuple[RawBody, Box | Polyhedron]] = []
    fixtures: list[tuple[RawBody, Box | Polyhedron]] = []
    bad: list[tuple[RawBody, FloatArray | None, str]] = []  # parts that cannot be read: (body, vertices [m], why)
    for b in found.bodies:
        role = body_role(b.name, b.layer, spec)
        if role == "ignored":
            warnings.append(f"{src}: {b.where} ignored: neither a parts nor a fixtures layer (map.layers)")
            continue
        if b.mesh is None:
            if role == "fixture":
                warnings.append(f"{src}: fixture {b.where} {b.reason}; it is no obstacle for the arm")
            else:
                bad.append((b, None, b.reason))
            continue
        v, faces = b.mesh[0] * scale, b.mesh[1]
        body: Box | Polyhedron
        try:
            body = fit_box(v, faces, b.name)
        except MapError as exc:
            if role == "part":  # not a box: a closed polyhedral body will do
                try:
                    body = fit_polyhedron(v, faces, b.name, BOX_TOL)
                except MapError as poly_exc:
                    bad.append((b, v, poly_exc.message.removeprefix(f"part {b.name} ")))
                    continue
            else:
                why = exc.message.removeprefix(f"part {b.name} ")
                if n_open := open_edges(v, faces):
                    why += f" (not closed: {_plural(n_open, 'edge')} on one face only)"
                body = bounding_box(v)
                warnings.append(f"{src}: fixture {b.where} {why}; its bounding box is the obstacle")
        if zero := zero_area_faces(v, faces):
            warnings.append(f"{src}: {b.where} has {_plural(zero, 'zero-area face')} (ignored)")
        (parts if role == "part" else fixtures).append((b, body))
    return _named(parts), _named(fixtures), bad


def _place(
    seams: list[tuple[MapSeam, RawSeam]],
    parts: list[Part],
    fixtures: list[Part],
    bad: list[tuple[RawBody, FloatArray | None, str]],
    src: str,
    warnings: list[str],
) -> tuple[list[MapSeam], list[UnsupportedSeam]]:
    """Seams on parts stay; seams on a fixture become unsupported; a body that cannot be read (not closed,
    self-intersecting, ...) refuses the map only when it holds a seam (or may: an unreadable body when a seam
    touches no part), else it is skipped with a warning."""
    kept, unsupported, loose = [], [], []
    pts = np.array([[s.p_start, s.p_end, (s.p_start + s.p_end) / 2.0] for s, _ in seams]).reshape(-1, 3, 3)
    on_parts, on_fixtures = _touching(parts, pts), _touching(fixtures, pts)
    for i, (s, raw) in enumerate(seams):
        on = [p for p, t in zip(parts, on_parts[i], strict=True) if t]
        fx = [f for f, t in zip(fixtures, on_fixtures[i], strict=True) if t]
        if fx and len(on) < 2:
            why = f"{raw.where}: on fixture {fx[0].name}: a fixture is never welded (map.layers says what is a part)"
            unsupported.append(UnsupportedSeam(s.id, why, Unsupported.ON_FIXTURE))
            continue
        kept.append(s)
        if len(on) < 2:  # a seam joins two parts: the other one may be a body that could not be read
            loose.append((s, on))
    for b, v, why in bad:
        held = [s.id for s, raw in seams if _near(v, np.array([s.p_start, s.p_end]))]
        if held:
            raise MapError(
                f"{src}: {b.where}: part {b.name} {why}; it holds seam {held[0]}: parts must be closed bodies "
                "(a body that holds no seam is skipped with a warning)"
            )
        if v is None and loose:
            raise MapError(
                f"{src}: {b.where} {why}; seam {loose[0][0].id} touches {len(loose[0][1])} of the two parts it "
                "joins, so it may lie on this body"
            )
        warnings.append(f"{src}: {b.where}: part {b.name} {why}; skipped (it holds no seam)")
    for s, on in loose:
        what = f"only part {on[0].name}" if on else "no part"
        warnings.append(f"{src}: seam {s.id} touches {what} (within {TOUCH_M * 1000:.0f} mm); a seam joins two parts")
    return kept, unsupported


def _curved(
    found: Found, parts: list[Part], fixtures: list[Part], scale: float, src: str, warnings: list[str]
) -> tuple[list[CurvedSeam], list[UnsupportedSeam]]:
    """The curved seams [m] with their joints; one on a fixture (and not on two parts) is unsupported."""
    curved, unsupported = [], []
    for raw in found.curves:
        curve = raw.curve.scaled(scale)
        if curve.length < MIN_SEAM_LENGTH:
            raise MapError(f"{src}: seam {raw.id} has zero length ({raw.where}); a seam needs two distinct end points")
        seam = CurvedSeam(raw.id, curve, str(raw.where))
        joint, why = curved_joint(seam, parts)
        if joint is None:
            fx = [f for f in fixtures if bool(np.all(f.contains(curve.sample(0.01), TOUCH_M)))]
            if fx:
                why = (
                    f"{raw.where}: on fixture {fx[0].name}: a fixture is never welded (map.layers says what is a part)"
                )
                unsupported.append(UnsupportedSeam(raw.id, why, Unsupported.ON_FIXTURE))
                continue
            warnings.append(f"{src}: curved seam {raw.id} ({raw.where}) {why}")
        curved.append(CurvedSeam(raw.id, curve, str(raw.where), joint, why))
    return curved, unsupported


def read_map(path: str | Path, units: str | None = None, layers: LayerPatterns | None = None) -> WeldMap:
    """Read a DXF welding map into a :class:`WeldMap` in frame ``M`` [m].

    units : ``"mm"``, ``"cm"``, ``"m"`` or ``"in"`` (``--units`` / ``map.units``); wins over the file's
        ``$INSUNITS``, with a warning when they disagree. layers : which layers hold parts, fixtures and seams
        (the scenario's ``map.layers``; default :class:`LayerRoles`).
    Raises MapError (MapUnitsError for units) with a one-line message on any unreadable or unusable file; what
    was skipped or doubted is in ``WeldMap.warnings`` and logged on ``cell.weldmap``.
    """
    path = Path(path)
    src = str(path)
    spec: LayerPatterns = layers if layers is not None else LayerRoles()
    if units is not None:  # a bad override is the caller's error: refused before reading the file
        resolve_units(0, units, src)
    with ezdxf_to_log():
        doc = load(path)
        try:
            found = Reader(doc, src, spec).read(doc.modelspace())
            code = int(doc.header.get("$INSUNITS", 0) or 0)
        except MapError:
            raise
        except MALFORMED as exc:
            raise MapError(f"{src}: malformed DXF content ({kind_of(exc)}: {exc})") from None
    _check_content(found, doc, src)
    unit, warnings = resolve_units(code, units, src)
    scale = METRES_PER_UNIT[unit]
    _check_extent(found, scale, src)
    P = _points(found)
    if len(P) and (w := extent_warning(float(np.ptp(P, axis=0).max()), unit, src)):
        warnings.append(w)
    seams = _seams(found, scale, src)
    parts, fixtures, bad = _bodies(found, spec, scale, src, warnings)
    kept, unsupported = _place(seams, parts, fixtures, bad, src, warnings)
    curved, on_fixtures = _curved(found, parts, fixtures, scale, src, warnings)
    unsupported += on_fixtures
    if not kept and not curved:
        first = unsupported[0].reason if unsupported else ""
        raise MapError(f"{src}: no seam can be welded: {_plural(len(unsupported), 'seam')} unsupported ({first})")
    if not parts:
        raise MapError(f"{src}: no parts (every body is a fixture or skipped); {WHAT}")
    for w in warnings:
        log.warning(w)
    return WeldMap(
        parts=tuple(parts),
        seams=tuple(kept),
        units=unit,
        source=src,
        frame="M",
        fixtures=tuple(fixtures),
        unsupported=tuple(unsupported),
        warnings=tuple(warnings),
        curved=tuple(curved),
    )
