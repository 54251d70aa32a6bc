"""The station renders the map's fixtures where the part really lies: the cameras see clamps as in the real cell."""

from __future__ import annotations

import dataclasses

import numpy as np

from cell import scenario as sc
from cell.geometry import make_pose
from cell.pipeline import read_weldmap
from cell.sim.asbuilt.parts import as_built_fixtures
from cell.sim.cell import FIXTURE_PREFIX
from cell.station.sim import SimStation
from cell.types import Box, Part


def test_a_maps_fixture_is_a_body_of_the_station_at_its_as_built_place() -> None:
    s = sc.load("fence1")
    weldmap = read_weldmap(s)
    clamp = Part("CLAMP", Box(make_pose(p=(0.7, 0.35, 0.04)), np.array([0.05, 0.05, 0.08])), "3DSOLID")
    weldmap = dataclasses.replace(weldmap, fixtures=(clamp,))
    with SimStation(s, weldmap, arm=None) as station:
        body = station.sim.body_id(FIXTURE_PREFIX + "CLAMP")
        p_W, _ = station.sim.client.getBasePositionAndOrientation(body)
    (expected,) = as_built_fixtures(weldmap, s)
    assert np.allclose(p_W, expected.center, atol=1e-6)
