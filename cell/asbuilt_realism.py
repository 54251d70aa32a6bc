"""Which realism options shape which as-built part (``simulation.bow``, ``simulation.gaps``: bent in an arc, ends cut
out of square) and the tack welds' beads of ``simulation.tacks_present`` (docs/bodies.md section 7). Nothing here
runs when the options are off."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from cell.asbuilt_shapes import bowed, cut_end, principal_frame, tack_bead
from cell.errors import ScenarioError
from cell.geometry import FloatArray
from cell.scenario import BowSpec, Scenario, TacksPresentSpec
from cell.seams.joint import find_joints
from cell.seams.truth import true_seam_W, weld_face_plane
from cell.types import Joint, Part, Polyhedron, WeldMap

Shaper = Callable[[Polyhedron], Polyhedron]
TACK_PREFIX = "tack:"  # body names of the tack welds' beads: ``tack:<seam id>:start`` / ``:end``


def shapers(
    weldmap_M: WeldMap, scenario: Scenario, X_WM: FloatArray, joints: Mapping[str, Joint] | None = None
) -> dict[str, Shaper]:
    """Part name -> how its deviated body (in W) is shaped as built; empty when no bow and no gaps are asked.
    ``joints``: the map's (found here when gaps need them and none are given)."""
    sim = scenario.simulation
    names = {p.name for p in weldmap_M.parts}
    steps: dict[str, list[Shaper]] = {}
    bows = list(sim.bow)
    for key, dev in sim.deviations.items():
        if dev.bow_mm != 0.0:
            bows.append(BowSpec(part=key, mm=dev.bow_mm))
    for bow in bows:
        name = _part_named(bow.part, names)
        if name in steps:
            raise ScenarioError(f"part {name} is bowed twice (simulation.bow and deviations.{name}.bow_mm); give one")
        steps[name] = [_bow_step(bow)]
    if sim.gaps is not None:
        max_m = sim.gaps.max_mm / 1000.0
        found = find_joints(weldmap_M) if joints is None else joints
        for (abutting, receiving, end_face), across_M in _junctions(weldmap_M, found).items():
            sign = 1.0 if scenario.rng(f"gaps/{abutting}>{receiving}").uniform() < 0.5 else -1.0
            across_W = sign * (np.asarray(X_WM, dtype=float)[:3, :3] @ across_M)
            steps.setdefault(abutting, []).append(_gap_step(end_face, across_W, max_m))
    return {name: _chain(fns) for name, fns in steps.items()}


def _chain(fns: Sequence[Shaper]) -> Shaper:
    def run(body: Polyhedron) -> Polyhedron:
        for f in fns:
            body = f(body)
        return body

    return run


def _part_named(key: str, names: set[str]) -> str:
    """The map's part ``key`` names: exactly, else ignoring case; ScenarioError naming the parts otherwise."""
    found = [key] if key in names else sorted(n for n in names if n.lower() == key.lower())
    if len(found) != 1:
        raise ScenarioError(
            f"simulation.bow.part {key!r} names no one part; parts of the map: {', '.join(sorted(names))}"
        )
    return found[0]


def _bow_step(bow: BowSpec) -> Shaper:
    def step(body: Polyhedron) -> Polyhedron:
        X_AP, _, _ = principal_frame(body)
        if bow.toward is None:  # the cross axis nearer the horizontal: a part lying on the table stays on it
            toward = 1 if abs(X_AP[2, 1]) <= abs(X_AP[2, 2]) else 2
        else:
            toward = 1 if bow.toward == "y" else 2
        try:
            return bowed(body, X_AP, bow.mm / 1000.0, toward, bow.segments)
        except ScenarioError as e:
            raise ScenarioError(f"simulation.bow of part {bow.part}: {e}") from None

    return step


def _gap_step(end_face: str, across_W: FloatArray, max_m: float) -> Shaper:
    def step(body: Polyhedron) -> Polyhedron:
        faces = [n for n in body.names if n == end_face or n.startswith(end_face + "@")]
        if not faces:  # pragma: no cover - the joint's faces come from the same body
            raise ScenarioError(f"simulation.gaps: the as-built body has no end face {end_face}")
        return cut_end(body, faces[0], across_W, max_m)

    return step


def _junctions(weldmap_M: WeldMap, joints: Mapping[str, Joint]) -> dict[tuple[str, str, str], FloatArray]:
    """(abutting, receiving, one of A's end faces there) -> the unit direction (3,) in M of the junction's most
    horizontal seam (the one nearest to M's x-y plane; the first in map order on a tie): the direction the gap
    opens along. A junction is one end of A against one face plane of B."""
    out: dict[tuple[str, str, str], FloatArray] = {}
    seen: dict[tuple[str, str, tuple[float, ...]], tuple[str, float]] = {}
    for seam in weldmap_M.seams:
        j: Joint = joints[seam.id]
        n, d = weldmap_M.part(j.abutting).face_plane(j.end_face)
        key = (j.abutting, j.receiving, tuple(np.round([*n, d], 5)))
        u = seam.direction
        tilt = abs(float(u[2]))
        if key not in seen or tilt < seen[key][1] - 1e-9:
            if key in seen:
                del out[(j.abutting, j.receiving, seen[key][0])]
            seen[key] = (j.end_face, tilt)
            out[(j.abutting, j.receiving, j.end_face)] = np.asarray(u, dtype=float)
    return out


def as_built_tacks(
    weldmap_M: WeldMap, parts_W: Sequence[Part], spec: TacksPresentSpec, joints: Mapping[str, Joint]
) -> tuple[Part, ...]:
    """The tack welds' beads in W: at both ends of every seam of the map, a fillet bead ``spec.length_mm`` long (at
    most half the seam) with legs ``spec.leg_mm``, in the corner of the two as-built weld faces along the true
    seam. Named ``tack:<seam id>:start`` and ``:end``, drawn as ``"tack"``. ``joints``: the map's."""
    leg = spec.leg_mm / 1000.0
    out: list[Part] = []
    by_name = {p.name: p for p in parts_W}
    for seam in weldmap_M.seams:
        j = joints[seam.id]
        p0, p1 = true_seam_W(weldmap_M, j, parts_W)
        length = float(np.linalg.norm(p1 - p0))
        if length <= 0.0:
            continue
        u = (p1 - p0) / length
        run = min(spec.length_mm / 1000.0, length / 2.0)
        mid = (p0 + p1) / 2.0
        n_a, _ = weld_face_plane(by_name[j.abutting], j.face_abutting, mid)
        n_b, _ = weld_face_plane(by_name[j.receiving], j.face_receiving, mid)
        for end, (a, b) in (("start", (p0, p0 + run * u)), ("end", (p1 - run * u, p1))):
            out.append(Part(f"{TACK_PREFIX}{seam.id}:{end}", tack_bead(a, b, n_a, n_b, leg), "tack"))
    return tuple(out)
