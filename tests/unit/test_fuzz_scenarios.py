"""Nonsense scenarios (tools/scenario_fuzz.py: seeded mutations of the shipped ones) are refused in one line or
flagged by ``cell scenario check``, never silently accepted and never a traceback; and the strict reading each
kind relies on, one test each. The full count is benchmarks/bench_fuzz_scenarios.py."""

from __future__ import annotations

import pytest
import yaml
from tools_loader import load_tool

from cell import scenario as sc
from cell.errors import ScenarioError
from cell.pipeline.geometry import robot_arm

fuzz = load_tool("scenario_fuzz")
FENCE1 = (sc.SCENARIO_DIR / "fence1.yaml").read_text()


def load_text(text: str) -> sc.Scenario:
    return sc.from_yaml(text, sc.SCENARIO_DIR, "test.yaml")


def fence1_with(**top: object) -> str:
    return yaml.safe_dump({**yaml.safe_load(FENCE1), **top}, sort_keys=False)


def test_a_seeded_sample_is_refused_or_flagged_never_silent() -> None:
    verdicts = [fuzz.judge(m) for m in fuzz.mutants(seed=7, n=30, sources=("fence1", "bracket"))]
    s = fuzz.summary(verdicts)
    assert s["traceback"] == 0 and s["silent"] == 0, s["not_flagged"]
    assert s["refused"] >= 15 and s["flagged"] >= 3  # both answers are exercised
    for v in verdicts:
        assert v.lines and all("\n" not in line for line in v.lines)


def test_the_generator_is_deterministic_and_covers_every_kind() -> None:
    a, b = fuzz.mutants(seed=3, n=len(fuzz.KINDS)), fuzz.mutants(seed=3, n=len(fuzz.KINDS))
    assert [m.text for m in a] == [m.text for m in b]
    assert {m.kind for m in a} == set(fuzz.KINDS)


def test_a_key_given_twice_is_refused_naming_the_key_and_its_lines() -> None:
    text = FENCE1.replace("seed: 12\n", "seed: 12\nseed: 13\n")
    with pytest.raises(ScenarioError, match=r"key 'seed' is given twice in one mapping \(lines 6 and 7\)"):
        load_text(text)


@pytest.mark.parametrize(("value", "needed"), [('"12"', "a number"), ("true", "a number"), ("12.5", "integer")])
def test_seed_is_typed(value: str, needed: str) -> None:
    with pytest.raises(ScenarioError, match=f"seed: .*{needed}"):
        load_text(FENCE1.replace("seed: 12\n", f"seed: {value}\n"))


def test_yaml_1_2_exponents_are_numbers_and_absurd_ones_refused() -> None:
    scn = load_text(FENCE1.replace("size_m: [2.0, 1.2, 0.10]", "size_m: [2.0, 1.2, 1e-1]"))
    assert scn.table.size_m[2] == pytest.approx(0.1)
    with pytest.raises(ScenarioError, match=r"cameras.cam_right.eye_m.0: 1e\+300 is absurd"):
        load_text(FENCE1.replace("eye_m: [1.0, 0.0, 2.0]", "eye_m: [1e300, 0.0, 2.0]"))
    with pytest.raises(ScenarioError, match=r"cameras.cam_right.eye_m.0: Input should be less than or equal to 100"):
        load_text(FENCE1.replace("eye_m: [1.0, 0.0, 2.0]", "eye_m: [500.0, 0.0, 2.0]"))


def test_a_loose_weld_gate_needs_its_opt_in() -> None:
    with pytest.raises(ScenarioError, match=r"weld_tolerance_mm 100 is over 2: .*allow_loose_gate: true"):
        load_text(fence1_with(rescan={"weld_tolerance_mm": 100.0}))
    with pytest.raises(ScenarioError, match=r"bound_sigmas 0\.1 is outside 2 to 6"):
        load_text(fence1_with(rescan={"bound_sigmas": 0.1}))
    scn = load_text(fence1_with(rescan={"weld_tolerance_mm": 100.0, "allow_loose_gate": True}))
    assert scn.rescan.loose_gate() == ["weld_tolerance_mm 100 is over 2"]


def test_a_camera_or_the_robot_inside_the_table_is_refused() -> None:
    with pytest.raises(ScenarioError, match=r"cameras.cam_left.eye_m \[0.0, 0.0, 0.85\] is inside the table"):
        load_text(FENCE1.replace("eye_m: [-0.7, 0.0, 2.0]", "eye_m: [0.0, 0.0, 0.85]"))
    with pytest.raises(ScenarioError, match=r"robot.X_WR.xyz_m \[0.15, 0.0, 0.84\] is inside the table"):
        load_text(FENCE1.replace("xyz_m: [0.15, -1.05, 0.90]", "xyz_m: [0.15, 0.0, 0.84]"))


def test_home_outside_a_joints_limits_is_refused_as_the_run_would() -> None:
    scn = load_text(FENCE1.replace("home_deg: [-90.0,", "home_deg: [-200.0,"))
    with pytest.raises(ScenarioError, match=r"robot.home_deg A1 -200 deg is outside the joint's limits \(-\d+ to \d+"):
        robot_arm(scn)
    with pytest.raises(ScenarioError, match=r"robot\.home_deg\.0: Input should be greater than or equal to -360"):
        load_text(FENCE1.replace("home_deg: [-90.0,", "home_deg: [-400.0,"))


def test_check_names_the_part_drawn_in_the_air_and_its_height() -> None:
    from cell import pipeline
    from cell.scenario.layout_checks import part_height_problems

    scn = load_text(FENCE1.replace("X_WM: {xyz_m: [-0.55, -0.40, 0.90]}", "X_WM: {xyz_m: [-0.55, -0.40, 1.40]}"))
    (line,) = part_height_problems(scn, pipeline.read_weldmap(scn))
    assert "is drawn 0.500 m above the table top" in line and "set map.X_WM.xyz_m z to 0.900" in line
    assert line.startswith("part ") and line.split()[1] in {"TOP_RAIL", "BOTTOM_RAIL", "POST_L", "POST_R"}


def test_the_committed_full_count_is_clean_and_quoted_in_the_results() -> None:
    import json

    results = fuzz.REPO / "benchmarks" / "results" / "fuzz_scenarios.json"
    data = json.loads(results.read_text())
    assert data["n"] >= 200 and data["silent"] == 0 and data["traceback"] == 0
    assert data["kinds"] == list(fuzz.KINDS) and data["refused"] + data["flagged"] == data["n"]
    row = f"| now | {data['n']} | {data['refused']} | {data['flagged']} | 0 | 0 |"
    assert row in (fuzz.REPO / "docs" / "results.md").read_text()
