"""cell sweep's varied builds: run k is reproducible from (scenario seed, k) alone, each kind of variation drawn
from its own stream, within the paper's tolerances, and applied to the scenario as the simulation reads it."""

from __future__ import annotations

import numpy as np
import pytest

from cell import scenario as sc
from cell.errors import UsageError
from cell.geometry import make_pose
from cell.sweep import VARY_WORDS, Tolerances, parse_vary, variation, variations, varied
from cell.types import Box, MapSeam, Part, WeldMap

RAIL = Part("TOP_RAIL", Box(make_pose(p=[0.7, 0.75, 0.05]), np.array([1.4, 0.1, 0.1])))
POST = Part("POST_L", Box(make_pose(p=[0.24, 0.35, 0.04]), np.array([0.08, 0.7, 0.08])))
SEAM = MapSeam("POST_L>TOP_RAIL:+z", np.array([0.2, 0.7, 0.08]), np.array([0.28, 0.7, 0.08]))
WELDMAP = WeldMap((RAIL, POST), (SEAM,), "mm", "test")


@pytest.fixture(scope="module")
def fence1() -> sc.Scenario:
    return sc.load("fence1")


def test_run_k_is_the_same_whatever_n_and_whatever_ran_before(fence1: sc.Scenario) -> None:
    many = variations(fence1, WELDMAP, 6, VARY_WORDS)
    assert variation(fence1, WELDMAP, 4, VARY_WORDS) == many[4]
    assert variations(fence1, WELDMAP, 3, VARY_WORDS) == many[:3]
    # different runs draw different builds and seeds
    assert len({v.seed for v in many}) == 6
    assert many[0].deviations_mm != many[1].deviations_mm


def test_each_kind_has_its_own_stream(fence1: sc.Scenario) -> None:
    both = variation(fence1, WELDMAP, 2, ("tolerances", "placement"))
    alone = variation(fence1, WELDMAP, 2, ("placement",))
    assert alone.placement == both.placement  # varying tolerances too does not move the placement drawn
    assert alone.deviations_mm is None and alone.seed is None and alone.extrinsics is None
    other = variation(fence1.model_copy(update={"seed": fence1.seed + 1}), WELDMAP, 2, ("placement",))
    assert other.placement != alone.placement  # keyed by the scenario's seed


def test_deviations_within_the_paper_tolerances(fence1: sc.Scenario) -> None:
    tol = Tolerances()
    runs = variations(fence1, WELDMAP, 40, ("tolerances",))
    rail = np.array([v.deviations_mm["TOP_RAIL"][0] for v in runs if v.deviations_mm])  # size [mm]
    post_offset = np.array([v.deviations_mm["POST_L"][1] for v in runs if v.deviations_mm])
    assert np.all(np.abs(rail[:, 0]) <= tol.length * 1400.0 + 1e-9)  # length: 5 % of 1400 mm
    assert np.all(np.abs(rail[:, 1:]) <= tol.width_height * 100.0 + 1e-9)  # width, height: 1 % of 100 mm
    assert np.all(np.abs(post_offset) <= tol.location * 700.0 + 1e-9)  # location: 1 % of the post's length
    assert np.all(post_offset[:, 2] == 0.0)  # the part rests on the table
    # a 3-sigma reading: the spread is about a third of the bound, not the bound
    assert 0.2 < np.std(rail[:, 0]) / (tol.length * 1400.0) < 0.5


def test_varied_scenario_carries_the_drawn_values(fence1: sc.Scenario) -> None:
    v = variation(fence1, WELDMAP, 1, VARY_WORDS)
    s = varied(fence1, v)
    assert v.deviations_mm is not None and v.placement is not None and v.extrinsics is not None
    assert s.deviations["POST_L"].size_mm == v.deviations_mm["POST_L"][0]
    assert s.simulation.placement_error.xyz_m[:2] == v.placement[:2]
    assert s.simulation.placement_error.rpy_deg[2] == v.placement[2]
    assert s.cameras["cam_left"].extrinsic_error.translation_mm == v.extrinsics["cam_left"][0]
    assert s.seed == v.seed
    assert varied(fence1, variation(fence1, WELDMAP, 1, ("seed",))).deviations == fence1.deviations  # kept


def test_parse_vary() -> None:
    assert parse_vary("seed, tolerances") == ("tolerances", "seed")  # canonical order
    with pytest.raises(UsageError, match=r"unknown word.*colour.*valid: tolerances, placement"):
        parse_vary("tolerances,colour")
    with pytest.raises(UsageError, match="nothing to vary"):
        parse_vary(" , ")
