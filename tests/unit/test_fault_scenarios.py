"""The fault scenario files (scenarios/faults/) and the ``faults`` section: bad sections are ScenarioErrors naming
the key, and each shipped fault scenario is fence1 but for its fault. What the pipeline makes of them:
tests/scenario/test_faults.py."""

from __future__ import annotations

import pytest

from cell import pipeline
from cell import scenario as sc
from cell.errors import ScenarioError


@pytest.mark.parametrize(
    ("faults", "expected"),
    [
        ("faults: {cameras: {cam_nope: {mode: dead}}}", "simulation.faults.cameras names unknown camera(s) cam_nope"),
        ("faults: {cameras: {cam_left: {mode: melted}}}", "simulation.faults.cameras.cam_left.mode"),
        ("faults: {cameras: {cam_left: {mode: salt, fraction: 1.5}}}", "fraction"),
        ("faults: {occluder: {}}", "unknown key 'simulation.faults.occluder' (did you mean 'occluders'?)"),
        ("faults: {occluders: {clamp: {center_m: [0, 0, 1], size_m: [0.1, 0.1, -0.1]}}}", "size_m"),
    ],
)
def test_bad_faults_sections_are_scenario_errors(faults: str, expected: str) -> None:
    text = (sc.SCENARIO_DIR / "fence1.yaml").read_text() + "  " + faults + "\n"  # in fence1's simulation section
    with pytest.raises(ScenarioError) as exc:
        sc.from_yaml(text, sc.SCENARIO_DIR, "test.yaml")
    assert expected in exc.value.message


def test_an_unknown_missing_part_is_a_scenario_error() -> None:
    s = sc.load("faults/missing-part")
    bad = s.with_simulation(faults=sc.FaultsSpec(missing_parts=("POST_X",)))
    with pytest.raises(ScenarioError, match=r"faults\.missing_parts names unknown part"):
        pipeline.detect(bad)  # before any camera renders


def test_fault_scenarios_differ_from_fence1_only_in_their_fault() -> None:
    skip = {"name", "description", "map", "cameras", "perception"}
    fence1 = sc.load("fence1")
    base = (fence1.model_dump(exclude=skip), fence1.simulation.model_dump(exclude={"faults", "placement_error"}))
    for name in sc.available():
        if name.startswith("faults/") and name != "faults/ladder-shifted":
            s = sc.load(name)
            mine = (s.model_dump(exclude=skip), s.simulation.model_dump(exclude={"faults", "placement_error"}))
            mine[0]["simulation"], base[0]["simulation"] = None, None
            assert mine == base, name
            assert set(s.cameras) == {"cam_right", "cam_left", "eye_in_hand"}
