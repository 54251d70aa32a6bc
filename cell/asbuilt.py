"""The part as it was really built: the map's designed parts with the scenario's deviations, placed in the world.

Deviations are given per part in the part's own box frame B (size and offset in mm, rotation in degrees about the
part centre). After the deviations, every part is dropped (or lifted) so that its lowest corner rests on the table:
a part lies on the table, it does not float or sink into it. The result is the ground truth of the simulation.
"""

from __future__ import annotations

import numpy as np

from cell.errors import ScenarioError
from cell.geometry import make_pose, rpy_to_matrix
from cell.scenario import Deviation, Scenario
from cell.types import Box, Part, WeldMap


def as_built_parts(weldmap_M: WeldMap, scenario: Scenario) -> tuple[Part, ...]:
    """The as-built parts in the world frame W.

    weldmap_M : the designed map, frame ``"M"``.
    Returns one :class:`Part` per designed part, same names and order, boxes in W.
    """
    names = {p.name for p in weldmap_M.parts}
    deviations = _by_part(scenario.deviations, names)
    X_WM = scenario.X_WM @ scenario.simulation.placement_error.X  # true placement, not the nominal one
    table_top = scenario.table.top_z
    parts = []
    for part in weldmap_M.parts:
        dev = deviations.get(part.name)
        box_W = part.box.transformed(X_WM)
        if dev is not None:
            size = box_W.size + np.asarray(dev.size_mm) / 1000.0
            if np.any(size <= 0):
                raise ScenarioError(f"deviations.{part.name}.size_mm makes the part's size non-positive")
            # Offset and rotation are about the part's own centre, along its own axes.
            X_B_Bdev = make_pose(rpy_to_matrix(np.radians(dev.rpy_deg)), np.asarray(dev.offset_mm) / 1000.0)
            box_W = Box(box_W.X_AB @ X_B_Bdev, size)
        lowest = float(box_W.corners()[:, 2].min())
        X = box_W.X_AB.copy()
        X[2, 3] += table_top - lowest  # rest on the table
        parts.append(Part(part.name, Box(X, box_W.size)))
    return tuple(parts)


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
