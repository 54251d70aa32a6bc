"""Property tests (hypothesis): mangled inputs give a valid result or one clear CellError, never a traceback.

Inputs: mutated copies of maps/fence1.dxf for :func:`cell.weldmap.read_map` (byte flips, truncation, deleted,
duplicated and swapped lines, duplicated spans, lines swapped far apart, swapped group codes, random text, extreme
numbers in coordinates) and of scenarios/fence1.yaml for
:func:`cell.scenario.from_yaml` (deleted or misspelled keys, wrong types, out-of-range values, random YAML).
Deterministic (derandomize) and bounded: each example has a 2 s deadline.
"""

from __future__ import annotations

import copy
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cell import scenario as sc
from cell.errors import CellError, MapError, ScenarioError
from cell.types import WeldMap
from cell.weldmap import MAX_COORD_M, read_map

REPO = Path(__file__).resolve().parents[2]
DXF = (REPO / "maps" / "fence1.dxf").read_bytes()
DXF_LINES = DXF.decode("ascii").splitlines(keepends=True)
# the value lines of coordinates (after group codes 10-38: x, y, z of points): where extreme numbers go
COORD_LINES = [i + 1 for i, line in enumerate(DXF_LINES[:-1]) if line.strip() in {str(c) for c in range(10, 39)}]
EXTREME = ["nan", "inf", "-inf", "1e300", "-1e300", "1e12", "-3.4e38", "1e-320", "0"]
SCENARIO = (sc.SCENARIO_DIR / "fence1.yaml").read_text()
SCENARIO_DATA = yaml.safe_load(SCENARIO)

FUZZ = settings(
    max_examples=60,
    deadline=2000,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    database=None,
)


def assert_one_clear_line(err: CellError) -> None:
    msg = err.message
    assert msg.strip(), f"{type(err).__name__} with an empty message"
    assert "\n" not in msg and "Traceback" not in msg, msg


def read_bytes(data: bytes, units: str | None = None) -> WeldMap:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "map.dxf"
        path.write_bytes(data)
        return read_map(path, units=units)


def check_map(data: bytes, units: str | None = None) -> None:
    try:
        weldmap = read_bytes(data, units)
    except MapError as err:  # MapUnitsError included
        assert_one_clear_line(err)
        return
    assert weldmap.parts and weldmap.seams
    for s in weldmap.seams:
        assert np.all(np.isfinite(s.p_start)) and np.all(np.isfinite(s.p_end)) and s.length > 0
        assert max(np.abs(s.p_start).max(), np.abs(s.p_end).max()) <= MAX_COORD_M  # plausible: within 10 km
    for p in (*weldmap.parts, *weldmap.fixtures):
        corners = p.box.corners()
        assert np.all(np.isfinite(corners)) and np.abs(corners).max() <= MAX_COORD_M + p.radius


# -- DXF mutations ------------------------------------------------------------------------------------------


@st.composite
def byte_flips(draw: st.DrawFn) -> bytes:
    data = bytearray(DXF)
    for _ in range(draw(st.integers(1, 20))):
        i = draw(st.integers(0, len(data) - 1))
        data[i] = draw(st.integers(0, 255))
    return bytes(data)


@st.composite
def line_edits(draw: st.DrawFn) -> bytes:
    lines = list(DXF_LINES)
    for _ in range(draw(st.integers(1, 8))):
        i = draw(st.integers(0, len(lines) - 1))
        kind = draw(st.sampled_from(["delete", "duplicate", "swap", "code", "text", "number"]))
        if kind == "delete":
            del lines[i]
        elif kind == "duplicate":
            lines.insert(i, lines[i])
        elif kind == "swap" and i + 1 < len(lines):
            lines[i], lines[i + 1] = lines[i + 1], lines[i]
        elif kind == "code":  # a group code line replaced by another group code
            code = draw(st.sampled_from([0, 1, 2, 5, 8, 10, 20, 30, 62, 70, 100, 330, 1000, 1001, 999]))
            lines[i] = f"{code:3d}\n"
        elif kind == "text":
            lines[i] = draw(st.text(alphabet=st.characters(min_codepoint=32, max_codepoint=126), max_size=20)) + "\n"
        else:
            lines[i] = repr(draw(st.floats(allow_nan=True, allow_infinity=True))) + "\n"
        if not lines:
            break
    return "".join(lines).encode("ascii", "replace")


@st.composite
def spans_and_numbers(draw: st.DrawFn) -> bytes:
    """What an outsider's tools do to a file: a span of lines duplicated, lines swapped far apart, coordinates
    replaced by extreme numbers (NaN, infinities, 1e300: the reader must refuse them, naming the entity)."""
    lines = list(DXF_LINES)
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["span", "far_swap", "extreme", "extreme"]))
        if kind == "span":
            i = draw(st.integers(0, len(lines) - 1))
            n = draw(st.integers(2, 60))
            j = draw(st.integers(0, len(lines)))
            lines[j:j] = lines[i : i + n]
        elif kind == "far_swap":
            i, j = draw(st.integers(0, len(lines) - 1)), draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        else:
            i = draw(st.sampled_from(COORD_LINES))
            if i < len(lines):
                lines[i] = draw(st.sampled_from(EXTREME)) + "\n"
    return "".join(lines).encode("ascii", "replace")


@FUZZ
@given(spans_and_numbers())
def test_dxf_with_duplicated_spans_and_extreme_numbers(data: bytes) -> None:
    check_map(data)


@pytest.mark.parametrize("value", ["nan", "-inf", "1e12"])
def test_an_extreme_coordinate_is_refused_or_harmless(value: str) -> None:
    # NaN, infinite and 1e12-metre coordinates must never enter the map.
    for i in COORD_LINES[:: max(1, len(COORD_LINES) // 3)]:
        lines = list(DXF_LINES)
        lines[i] = value + "\n"
        check_map("".join(lines).encode("ascii"))


@FUZZ
@given(byte_flips())
def test_dxf_with_flipped_bytes(data: bytes) -> None:
    check_map(data)


@FUZZ
@given(st.integers(0, len(DXF) - 1))
def test_truncated_dxf(n: int) -> None:
    check_map(DXF[:n])


@FUZZ
@given(line_edits())
def test_dxf_with_edited_lines(data: bytes) -> None:
    check_map(data)


@FUZZ
@given(st.binary(max_size=2000) | st.text(max_size=2000).map(lambda t: t.encode("utf-8")))
def test_random_bytes_as_dxf(data: bytes) -> None:
    check_map(data)


@FUZZ
@given(st.text(max_size=12))
def test_any_units_override(units: str) -> None:
    check_map(DXF, units)


# -- scenario mutations -------------------------------------------------------------------------------------


def paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every key path of a nested YAML value (dict keys and list indices)."""
    out = [prefix] if prefix else []
    if isinstance(node, dict):
        for k, v in node.items():
            out += paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += paths(v, (*prefix, i))
    return out


PATHS = paths(SCENARIO_DATA)
WEIRD = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**12), 10**12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=10),
    st.lists(st.floats(-1e3, 1e3), max_size=5),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=3),
)


@st.composite
def mutated_scenarios(draw: st.DrawFn) -> str:
    data = copy.deepcopy(SCENARIO_DATA)
    for _ in range(draw(st.integers(1, 4))):
        path = draw(st.sampled_from(PATHS))
        parent: Any = data
        try:
            for k in path[:-1]:
                parent = parent[k]
            key = path[-1]
            kind = draw(st.sampled_from(["delete", "misspell", "value", "scale", "negate"]))
            if kind == "delete":
                del parent[key]
            elif kind == "misspell" and isinstance(parent, dict):
                parent[str(key) + draw(st.sampled_from(["s", "_", "x"]))] = parent.pop(key)
            elif kind == "value":
                parent[key] = draw(WEIRD)
            elif isinstance(parent[key], int | float) and not isinstance(parent[key], bool):
                parent[key] = parent[key] * (-1.0 if kind == "negate" else draw(st.sampled_from([0.0, 1e9, -1e-9])))
        except (KeyError, IndexError, TypeError):
            continue  # an earlier mutation removed or replaced this path
    return yaml.safe_dump(data, sort_keys=False)


def check_scenario(text: str) -> None:
    try:
        s = sc.from_yaml(text, sc.SCENARIO_DIR, "fuzz.yaml")
    except ScenarioError as err:
        assert_one_clear_line(err)
        return
    assert s.cameras and s.name is not None
    s.X_WR, s.X_WM  # noqa: B018 - derived poses must not raise on a valid scenario
    for cam in s.cameras.values():
        assert np.all(np.isfinite(cam.X_WC))


@FUZZ
@given(mutated_scenarios())
def test_scenario_with_mutated_keys_and_values(text: str) -> None:
    check_scenario(text)


@FUZZ
@given(st.text(max_size=500))
def test_random_text_as_scenario(text: str) -> None:
    check_scenario(text)


@FUZZ
@given(st.integers(0, len(SCENARIO)), st.text(max_size=30))
def test_scenario_with_spliced_text(at: int, junk: str) -> None:
    check_scenario(SCENARIO[:at] + junk + SCENARIO[at:])


@pytest.mark.parametrize("n", [0, 10, 200, 1000])
def test_truncated_scenario(n: int) -> None:
    check_scenario(SCENARIO[:n])


# -- regressions found by the fuzzing above -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("eye_m: [1.0, 0.0, 2.0]", "eye_m: [.nan, 0.0, 2.0]"),
        ("eye_m: [1.0, 0.0, 2.0]", "eye_m: [.inf, 0.0, 2.0]"),
        ("X_WR: {xyz_m: [0.15, -1.05, 0.90]}", "X_WR: {xyz_m: [.nan, -1.05, 0.90]}"),
    ],
)
def test_non_finite_numbers_are_a_scenario_error(old: str, new: str) -> None:
    # Bug: pydantic accepts NaN/inf floats by default; a camera or robot pose then became NaN silently.
    assert old in SCENARIO
    with pytest.raises(ScenarioError, match="finite number"):
        sc.from_yaml(SCENARIO.replace(old, new, 1), sc.SCENARIO_DIR, "fuzz.yaml")
