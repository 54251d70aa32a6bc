"""Scenario loading: shipped scenarios validate, and every kind of bad input is one clear ScenarioError."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

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
        (("TOP_RAIL:    {size_mm", "TOP_RAIL:    {sizes_mm"), "unknown key 'deviations.TOP_RAIL.sizes_mm'"),
        (("seed: 12", "seed: -3"), "seed: Input should be greater than or equal to 0"),
        (("noise: realistic", "noise: loud"), "noise: Input should be 'none' or 'realistic'"),
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
    # f_px = 0.5 * width / tan(HFOV / 2) (REFERENCE section 2): D415 1280 px, 65 deg -> about 1004.6 px.
    assert cam.fx_px == pytest.approx(0.5 * 1280 / np.tan(np.radians(65) / 2))
    X = cam.X_WC
    np.testing.assert_allclose(X[:3, 3], cam.eye_m)
    forward = np.subtract(cam.target_m, cam.eye_m)
    np.testing.assert_allclose(X[:3, 2], forward / np.linalg.norm(forward))
