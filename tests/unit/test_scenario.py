"""Scenario loading: shipped scenarios validate, and every kind of bad input is one clear ScenarioError."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from cell import scenario as sc
from cell.errors import ScenarioError

FENCE1 = (sc.SCENARIO_DIR / "fence1.yaml").read_text()


def load_text(text: str) -> sc.Scenario:
    return sc.from_yaml(text, sc.SCENARIO_DIR, "test.yaml")


@pytest.mark.parametrize("name", ["fence1-exact", "fence1", "fence2"])
def test_shipped_scenarios_load(name: str) -> None:
    s = sc.load(name)
    assert s.name == name
    assert s.map_path.is_file()
    assert {"cam_left", "cam_right", "eye_in_hand"} <= set(s.cameras)
    # Paper cameras: fixed at (1, 0, 2) and (-0.7, 0, 2), eye-in-hand at (0.15, -1, 2.5).
    assert s.cameras["cam_right"].eye_m == (1.0, 0.0, 2.0)
    assert s.cameras["eye_in_hand"].mount == "eye_in_hand"


def test_names_and_paths_resolve_to_the_same_scenario() -> None:
    by_name = sc.load("fence1")
    by_path = sc.load(sc.SCENARIO_DIR / "fence1.yaml")
    assert by_name == by_path
    assert "fence1" in sc.available()


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (("seed: 12", "sed: 12"), "unknown key 'sed' (did you mean 'seed'?)"),
        (
            ("    eye_m: [1.0", "    eyes_m: [1.0"),
            "unknown key 'cameras.cam_right.eyes_m' (did you mean 'eye_m'?)",
        ),
        (("TOP_RAIL:    {size_mm", "TOP_RAIL:    {sizes_mm"), "unknown key 'simulation.deviations.TOP_RAIL.sizes_mm'"),
        (("seed: 12", "seed: -3"), "seed: Input should be greater than or equal to 0"),
        (("noise: realistic", "noise: loud"), "simulation.noise: Input should be 'none' or 'realistic'"),
        (
            ("file: ../maps/fence1.dxf", "file: ../maps/nope.dxf"),
            "map.file '../maps/nope.dxf' does not exist",
        ),
        (("size_m: [2.0, 1.2, 0.10]", "size_m: [2.0, 1.2, -0.10]"), "table.size_m.2"),
    ],
)
def test_bad_scenarios_name_the_key_and_what_is_valid(edit: tuple[str, str], expected: str) -> None:
    old, new = edit
    assert old in FENCE1
    with pytest.raises(ScenarioError) as exc:
        load_text(FENCE1.replace(old, new, 1))
    msg = str(exc.value)
    assert expected in msg
    assert "\n" not in msg


def test_unknown_key_lists_the_valid_keys() -> None:
    with pytest.raises(ScenarioError, match=r"valid keys there: .*eye_m.*target_m"):
        load_text(FENCE1.replace("    eye_m: [1.0", "    eyes_m: [1.0", 1))


@pytest.mark.parametrize("text", ["", "- a list", "key: [unclosed", "just a string"])
def test_not_a_mapping_or_not_yaml(text: str) -> None:
    with pytest.raises(ScenarioError):
        load_text(text)


def test_missing_scenario_names_the_available_ones(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match=r"available: .*fence1"):
        sc.load("fence9")
    with pytest.raises(ScenarioError, match="does not exist"):
        sc.load(tmp_path / "missing.yaml")


def test_rng_streams_are_reproducible_and_independent() -> None:
    s = sc.load("fence1")
    a1 = s.rng("cam_left").random(4)
    a2 = s.rng("cam_left").random(4)
    b = s.rng("cam_right").random(4)
    np.testing.assert_array_equal(a1, a2)
    assert not np.allclose(a1, b)
    other_seed = s.model_copy(update={"seed": s.seed + 1})
    assert not np.allclose(other_seed.rng("cam_left").random(4), a1)


def test_camera_focal_length_from_fov() -> None:
    cam = sc.load("fence1").cameras["cam_right"]
    # f_px = 0.5 * width / tan(HFOV / 2) (docs/reference.md section 2): D415 1280 px, 65 deg -> about 1004.6 px.
    assert cam.fx_px == pytest.approx(0.5 * 1280 / np.tan(np.radians(65) / 2))
    X = cam.X_WC
    np.testing.assert_allclose(X[:3, 3], cam.eye_m)
    forward = np.subtract(cam.target_m, cam.eye_m)
    np.testing.assert_allclose(X[:3, 2], forward / np.linalg.norm(forward))


# -- typed configuration: every stage's options are keys of the scenario ------------------------------------------


def with_keys(text: str) -> str:
    """fence1 with ``text``'s top-level YAML keys in place of its own (a key given twice is refused)."""
    data = {**yaml.safe_load(FENCE1), **yaml.safe_load(text)}
    return yaml.safe_dump(data, sort_keys=False)


@pytest.mark.parametrize(
    ("text", "key", "close"),
    [
        ("locator: {method: ours, options: {tube_radus_m: 0.05}}", "locator.options.tube_radus_m", "tube_radius_m"),
        ("locator: {method: ransac, options: {run: 5}}", "locator.options.run", "runs"),
        ("locator: {method: paper, option: {}}", "locator.option", "options"),
        ("motion: {gate: {rate_hzz: 500.0}}", "motion.gate.rate_hzz", "rate_hz"),
        (
            "motion: {plan: {collision: {part_inflaton: 0.003}}}",
            "motion.plan.collision.part_inflaton",
            "part_inflation",
        ),
        ("rescan: {closeup: {view: {distance_m: [0.4]}}}", "rescan.closeup.view.distance_m", "distances_m"),
        ("export: {krl: {load_k: 2.0}}", "export.krl.load_k", "load_kg"),
        ("simulation: {bead: {radius: 0.002}}", "simulation.bead.radius", "radius_m"),
    ],
)
def test_a_typo_inside_an_options_class_names_the_key_and_the_valid_ones(text: str, key: str, close: str) -> None:
    with pytest.raises(ScenarioError) as exc:
        load_text(with_keys(text))
    msg = str(exc.value)
    assert f"unknown key {key!r} (did you mean {close!r}?)" in msg
    assert "valid keys there: " in msg and close in msg.split("valid keys there: ")[1].split(", ")
    assert "\n" not in msg


def test_a_typo_in_perception_checks_and_closeup_options_is_named_too() -> None:
    perception = "perception:\n  workspace: {min_m: [-0.70, -0.55, 0.905], max_m: [1.0, 0.55, 1.20]}\n"
    text = FENCE1.split("perception:")[0] + perception + "  health: {min_agreemnt: 0.4}\n"
    with pytest.raises(ScenarioError, match=r"unknown key 'perception.health.min_agreemnt' \(did you mean"):
        load_text(text)
    with pytest.raises(ScenarioError, match=r"ours: unknown key 'target_se' \(did you mean 'target_se_m'\?\)"):
        load_text(with_keys("rescan: {closeup: {closeup_locator_options: {ours: {target_se: 0.001}}}}"))
    with pytest.raises(ScenarioError, match=r"locator.method 'ourz' is unknown \(did you mean 'ours'\?\)"):
        load_text(with_keys("locator: {method: ourz}"))


def test_option_values_are_checked_when_the_file_is_loaded() -> None:
    for text in (
        "locator: {method: paper, options: {frequency_bin_m: 0.0}}",  # a Bounds range
        "locator: {method: ours, options: {sample_share: 0.3}}",  # not a layer of the index
        "locator: {method: ransac, options: {cloud: sparse}}",
        "export: {krl: {arc_markers: shout}}",
    ):
        with pytest.raises(ScenarioError) as exc:
            load_text(with_keys(text))
        assert text.split(":")[0] in str(exc.value) and "\n" not in str(exc.value)


def test_every_options_class_is_reachable_from_the_scenario_with_its_defaults() -> None:
    from cell import config

    s = load_text(FENCE1)
    assert s.perception.health == config.HealthOptions()
    assert s.perception.symmetry == config.SymmetryOptions()
    assert s.perception.screen == config.ScreenOptions()
    assert s.motion.plan == config.PlanOptions() and s.motion.plan.collision == config.CollisionOptions()
    assert s.motion.gate == config.GateOptions()
    assert s.rescan.closeup == config.RescanOptions() and s.rescan.closeup.view == config.ViewOptions()
    assert s.export.krl == config.KrlOptions()
    assert s.simulation.bead == config.BeadStyle()
    assert s.locator == sc.OursLocatorSpec() and s.locator.options == config.OursSettings()
    # One number each: the re-scan threshold, ours' confidence scale, the stick-out.
    assert s.rescan.confidence_threshold == config.CONFIDENCE_THRESHOLD
    assert s.rescan.closeup.first_scale_m == config.OursSettings().target_se_m
    assert s.rescan.closeup.closeup_locator_options["ours"]["target_se_m"] == config.CLOSEUP_TARGET_SE_M
    assert s.robot.stickout_mm == config.STICKOUT_MM
    # Set in the file, they arrive typed.
    s = load_text(with_keys("motion: {gate: {rate_hz: 500}}\nlocator: {method: ransac, options: {runs: 5}}"))
    assert s.motion.gate == config.GateOptions(rate_hz=500.0)
    assert s.locator == sc.RansacLocatorSpec(options=config.RansacOptions(runs=5))


def test_the_method_names_come_from_one_registry() -> None:
    import typer

    from cell.cli.common import check_method
    from cell.seams.registry import LOCATORS, METHODS, locator_spec, with_method

    assert tuple(LOCATORS) == METHODS
    assert {name: sc.spec_method(entry.spec) for name, entry in LOCATORS.items()} == {m: m for m in METHODS}
    assert {sc.spec_method(s) for s in sc.LOCATOR_SPECS} == set(METHODS)  # the scenario's union, member for member
    with pytest.raises(typer.BadParameter, match=", ".join(METHODS)):
        check_method("ourz")
    # Another method than the scenario's runs with its own defaults, and the scenario says which ran.
    s = load_text(with_keys("locator: {method: ours, options: {target_se_m: 0.001}}"))
    assert locator_spec(s, "ours") is s.locator
    assert locator_spec(s, "ransac") == sc.RansacLocatorSpec()
    assert with_method(s, "paper").locator == sc.PaperLocatorSpec()
    assert with_method(s, None) is s


def test_the_closeup_merges_its_options_into_the_scenarios_locator() -> None:
    from cell.rescan.fusion import closeup_scenario

    s = load_text(with_keys("locator: {method: ours, options: {tube_radius_m: 0.05}}"))
    close = closeup_scenario(s, "ours", s.rescan.closeup).locator.options
    assert (close.target_se_m, close.edge_band_m, close.corner_band_m) == (0.00002, 0.002, 0.003)
    assert close.tube_radius_m == 0.05  # the scenario's own
    assert closeup_scenario(s, "paper", s.rescan.closeup) is s  # no close-up options for the paper's
