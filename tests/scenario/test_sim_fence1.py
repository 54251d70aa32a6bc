"""The simulated cell on a real scenario: fence1-exact's cameras, with no robot in the cell, see the as-built fence
and nothing else above the table (the tiny inline cell's tests: tests/unit/test_sim.py)."""

from __future__ import annotations

import numpy as np
import pytest
from pinhole import deproject

from cell import scenario as scn
from cell.sim import SimCell


def test_fence1_exact_cameras_see_the_parts() -> None:
    """The real scenario's cameras render the as-built fence (skipped until the map exists)."""
    map_path = scn.SCENARIO_DIR.parent / "maps" / "fence1.dxf"
    if not map_path.is_file():
        pytest.skip("maps/fence1.dxf not generated yet")
    from cell.sim.asbuilt.parts import as_built_parts
    from cell.weldmap import read_map

    scenario = scn.load("fence1-exact").with_noise("none")
    parts = as_built_parts(read_map(scenario.map_path, units=scenario.map.units), scenario)
    with SimCell(scenario, parts) as sim:
        for name, image in sim.capture_all().items():
            p_W = deproject(image)[image.depth > 0]
            on_parts = np.zeros(len(p_W), bool)
            for part in parts:
                on_parts |= part.box.contains(p_W, margin=0.001)
            assert on_parts.sum() > 10_000, name
            above = p_W[:, 2] > scenario.table.top_z + 0.002
            assert on_parts[above].mean() > 0.999, name  # what stands on the table is the fence
