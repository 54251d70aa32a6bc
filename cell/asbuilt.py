"""The part as it was really built: the map's designed parts with the scenario's deviations (in each part's own
frame), set down on the table when drawn on it, and the map's fixtures where the part really lies: the simulation's
ground truth (docs/bodies.md section 4)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from cell.asbuilt_realism import as_built_tacks, shapers
from cell.asbuilt_shapes import principal_frame
from cell.errors import ScenarioError
from cell.geometry import FloatArray, invert, make_pose, rpy_to_matrix, transform_points
from cell.scenario import Deviation, Scenario
from cell.seams.joint import find_joints
from cell.types import Box, Joint, Part, Polyhedron, WeldMap

# Which deviation keys each kind of body takes (the scenario's Deviation fields).
VALID_KEYS = {
    "box": ("size_mm", "offset_mm", "rpy_deg", "bow_mm"),
    "mesh": ("size_mm", "offset_mm", "rpy_deg", "bow_mm"),
}
ON_TABLE_M = 0.002  # [m] a part drawn this close to the table top rests on it
_DISTINCT = 1e-6  # principal spreads closer than this (relative) do not define a size change's axes


def as_built_parts(
    weldmap_M: WeldMap, scenario: Scenario, joints: Mapping[str, Joint] | None = None
) -> tuple[Part, ...]:
    """The as-built parts in the world frame W.

    weldmap_M : the designed map, frame ``"M"``.
    joints : the map's joints (``cell.seams.joint.find_joints``), when the caller has them; found here only when
        ``simulation.gaps`` needs them.
    Returns one :class:`Part` per designed part, same names, order and kind of body (box or polyhedron), in W.
    """
    names = {p.name for p in weldmap_M.parts}
    deviations = _by_part(scenario.deviations, names)
    X_WM = _true_placement(scenario)
    table_top = scenario.table.top_z
    shaped = shapers(weldmap_M, scenario, X_WM, joints)
    parts = []
    for part in weldmap_M.parts:
        dev = deviations.get(part.name)
        if dev is not None:
            _check_keys(part, dev)
        on_table = float(transform_points(X_WM, part.vertices())[:, 2].min()) - table_top <= ON_TABLE_M
        if part.is_box:
            box_W = part.box.transformed(X_WM)
            if dev is not None:
                box_W = _deviated_box(part.name, box_W, dev)
            if part.name not in shaped:
                X = box_W.X_AB.copy()
                if on_table:
                    X[2, 3] += table_top - float(box_W.corners()[:, 2].min())  # rest on the table
                parts.append(Part(part.name, Box(X, box_W.size), part.drawn_as))
                continue
            v_W, body = box_W.corners(), box_W.to_polyhedron()
        else:
            assert isinstance(part.body, Polyhedron)
            body = part.body
            v_W = transform_points(X_WM, _deviated_vertices(part.name, body, dev) if dev is not None else body.vertices)
        if part.name in shaped:  # bowed, or its ends cut out of square (docs/bodies.md section 7)
            shaped_W = shaped[part.name](Polyhedron(v_W, body.faces, body.names))
            v_W, body = np.array(shaped_W.vertices), shaped_W
        if on_table:
            v_W[:, 2] += table_top - float(v_W[:, 2].min())  # rest on the table
        parts.append(Part(part.name, Polyhedron(v_W, body.faces, body.names), part.drawn_as))
    return tuple(parts)


def as_built_fixtures(
    weldmap_M: WeldMap, scenario: Scenario, joints: Mapping[str, Joint] | None = None
) -> tuple[Part, ...]:
    """The map's fixtures in W, where the part really lies (the scenario's placement with its error); with
    ``simulation.tacks_present``, followed by the tack welds' beads (bodies named ``tack:<seam id>:start|end``,
    :func:`cell.asbuilt_realism.as_built_tacks`: the simulator renders them and moves them with the part)."""
    X_WM = _true_placement(scenario)
    fixtures = tuple(f.transformed(X_WM) for f in weldmap_M.fixtures)
    if scenario.simulation.tacks_present is None:
        return fixtures
    found = find_joints(weldmap_M) if joints is None else joints
    parts_W = as_built_parts(weldmap_M, scenario, found)
    return fixtures + as_built_tacks(weldmap_M, parts_W, scenario.simulation.tacks_present, found)


def _deviated_vertices(name: str, body: Polyhedron, dev: Deviation) -> FloatArray:
    """The body's vertices (k, 3) in its own frame after the deviation, taken in its principal frame P."""
    X_AP, extent, spread = principal_frame(body)
    size = np.asarray(dev.size_mm, dtype=float) / 1000.0
    if np.any(size != 0.0):
        gaps = np.abs(np.diff(spread)) <= _DISTINCT * max(float(spread[0]), 1e-300)
        ambiguous = [i for i in range(3) if size[i] != 0.0 and ((i > 0 and gaps[i - 1]) or (i < 2 and gaps[i]))]
        if ambiguous:
            raise ScenarioError(
                f"deviations.{name}.size_mm: part {name} is a mesh body whose principal axes "
                f"{', '.join('xyz'[i] for i in ambiguous)} are not distinct (equal spreads), so a size change has no "
                f"direction; valid for it: offset_mm and rpy_deg, or size_mm along distinct axes only"
            )
        if np.any(extent + size <= 0):
            raise ScenarioError(f"deviations.{name}.size_mm makes the part's size non-positive")
    scale = (extent + size) / extent
    X_P_Pdev = make_pose(rpy_to_matrix(np.radians(dev.rpy_deg)), np.asarray(dev.offset_mm) / 1000.0)
    v_P = transform_points(invert(X_AP), body.vertices) * scale
    return transform_points(X_AP @ X_P_Pdev, v_P)


def _deviated_box(name: str, box_W: Box, dev: Deviation) -> Box:
    size = box_W.size + np.asarray(dev.size_mm) / 1000.0
    if np.any(size <= 0):
        raise ScenarioError(f"deviations.{name}.size_mm makes the part's size non-positive")
    # Offset and rotation are about the part's own centre, along its own axes.
    X_B_Bdev = make_pose(rpy_to_matrix(np.radians(dev.rpy_deg)), np.asarray(dev.offset_mm) / 1000.0)
    return Box(box_W.X_AB @ X_B_Bdev, size)


def _check_keys(part: Part, dev: Deviation) -> None:
    """A deviation key this kind of body cannot take: a one-line ScenarioError naming the part and what is valid."""
    valid = VALID_KEYS[part.kind]
    extra = sorted(k for k in dev.model_dump(exclude_defaults=True) if k not in valid)
    if extra:
        raise ScenarioError(
            f"deviations.{part.name}: {', '.join(extra)} cannot be applied to part {part.name}, a {part.kind} body; "
            f"valid: {', '.join(valid)}"
        )


def _true_placement(scenario: Scenario) -> FloatArray:
    """X_WM (4, 4): where the map really lies (the nominal placement with the operator's error)."""
    return np.asarray(scenario.X_WM @ scenario.simulation.placement_error.X, dtype=float)


def _by_part(deviations: dict[str, Deviation], names: set[str]) -> dict[str, Deviation]:
    """The deviations keyed by the map's part names: a key matches its part exactly, else ignoring case (a map's
    part names keep their layer's case); a key that matches no part, or several ignoring case, is an error."""
    out: dict[str, Deviation] = {}
    unknown = []
    for key, dev in deviations.items():
        found = [key] if key in names else sorted(n for n in names if n.lower() == key.lower())
        if len(found) > 1:
            raise ScenarioError(f"deviations.{key} matches parts {', '.join(found)} ignoring case; name one exactly")
        if found:
            out[found[0]] = dev
        else:
            unknown.append(key)
    if unknown:
        raise ScenarioError(
            f"deviations name unknown part(s) {', '.join(sorted(unknown))}; "
            f"parts of the map: {', '.join(sorted(names))}"
        )
    return out
