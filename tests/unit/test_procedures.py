"""Weld procedures: the WPS table in a scenario (validated, a file beside it, the default from process:), which row
welds a seam (joint type, position, leg; vertical seams upwards), and the weave and pass geometry."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from tiny_cell import SIDE_SEAM, TOP_SEAM

from cell import scenario as sc
from cell.errors import ScenarioError
from cell.pipeline.detect import read_weldmap
from cell.process.procedures import joint_type, position, select_procedure
from cell.process.weave import cross_section, intended_offsets, pass_offsets, weave_lateral
from cell.seams.joint import find_joints
from cell.types.plan import NoProcedure, SeamProcedure, SeamTask
from cell.types.procedure import Weave, WeldPass, WeldProcedure

FENCE1 = (sc.SCENARIO_DIR / "fence1.yaml").read_text()
TOP, SIDE = SeamTask(*TOP_SEAM), SeamTask(*SIDE_SEAM)  # SIDE is drawn upwards (z 0 -> 60 mm)
SIDE_DOWN = SeamTask("side", SIDE.p_end, SIDE.p_start, SIDE.n_a, SIDE.n_b)


def _load(extra: str, base: Path = sc.SCENARIO_DIR) -> sc.Scenario:
    return sc.from_yaml(FENCE1 + extra, base)


def test_without_a_table_one_procedure_from_process() -> None:
    s = _load("process: {travel_speed_mm_s: 9.5, travel_angle_deg: 12}\n")
    (p,) = s.weld_procedures()
    assert (p.travel_speed_mm_s, p.travel_angle_deg, p.work_angle_deg) == (9.5, 12.0, 45.0)
    assert p.direction == "up" and not p.weave.active and len(p.passes) == 1


def test_table_rows_in_order_with_process_angles_where_not_given() -> None:
    s = _load("procedures:\n  - {name: a, travel_angle_deg: 5}\n  - {name: b, passes: [{lift_mm: 0}, {lift_mm: 2}]}\n")
    a, b = s.weld_procedures()
    assert (a.name, a.travel_angle_deg, b.travel_angle_deg) == ("a", 5.0, 10.0)
    assert [p.lift_mm for p in b.passes] == [0.0, 2.0]


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (
            "procedures:\n  - {name: a, curent_a: 200}\n",
            "unknown key 'procedures.0.curent_a' (did you mean 'current_a'?)",
        ),
        ("procedures:\n  - {name: a, weave: {pattern: zigzag, width_mm: 4}}\n", "procedures.0.weave"),
        (
            "procedures:\n  - {name: a, weave: {pattern: zigzag, width_mm: 4, frequency_hz: 2, dwell_s: [0.3, 0.2]}}\n",
            "leave no time to cross",
        ),
        ("procedures:\n  - {name: a, position: PX}\n", "procedures.0.position"),
        ("procedures:\n  - {name: a, leg_min_mm: 8, leg_max_mm: 4}\n", "leg_min_mm 8 > leg_max_mm 4"),
        ("procedures:\n  - {name: a}\n  - {name: a}\n", "each procedure name once"),
        ("procedures_file: nope.yaml\n", "procedures_file 'nope.yaml' cannot be read"),
    ],
)
def test_bad_tables_are_scenario_errors(extra: str, needle: str) -> None:
    with pytest.raises(ScenarioError) as err:
        _load(extra)
    assert needle in err.value.message


def test_procedures_file_is_read_beside_the_scenario(tmp_path: Path) -> None:
    (tmp_path / "wps.yaml").write_text("- {name: w, current_a: 150}\n")
    s = _load("procedures_file: wps.yaml\n", tmp_path)
    assert [p.current_a for p in s.weld_procedures()] == [150.0]
    with pytest.raises(ScenarioError, match="not both"):
        _load("procedures_file: wps.yaml\nprocedures: [{name: x}]\n", tmp_path)
    (tmp_path / "bad.yaml").write_text("name: w\n")
    with pytest.raises(ScenarioError, match="list of procedures"):
        _load("procedures_file: bad.yaml\n", tmp_path)


def test_position_from_gravity_and_the_faces() -> None:
    assert position(TOP.p_end - TOP.p_start, TOP.n_a, TOP.n_b) == "PB"  # horizontal, the bisector 45 deg up
    assert position(SIDE.p_end - SIDE.p_start, SIDE.n_a, SIDE.n_b) == "PF"
    assert position(SIDE.p_start - SIDE.p_end, SIDE.n_a, SIDE.n_b) == "PG"
    assert position([1, 0, 0], [0, 0.2, 1], [0, -0.2, 1]) == "PA"  # a flat fillet: the bisector straight up
    assert position([1, 0, 0], [0, 0, -1], [0, -1, 0]) == "PD"  # overhead horizontal-vertical
    assert position([0.2, 0, 1], [1, 0, 0], [0, -1, 0]) == "PF"  # 11 deg off vertical is vertical (30 deg)


def test_vertical_seams_are_welded_upwards_by_default() -> None:
    row = WeldProcedure("default")
    down = select_procedure(SIDE_DOWN, "T", 4.0, [row])
    assert isinstance(down, SeamProcedure) and down.reverse and down.fixed_direction and down.position == "PF"
    t = down.oriented(SIDE_DOWN)
    assert t.p_start[2] < t.p_end[2]
    up = select_procedure(SIDE, "T", 4.0, [row])
    assert isinstance(up, SeamProcedure) and not up.reverse and up.fixed_direction
    assert isinstance(s := select_procedure(SIDE, "T", 4.0, [WeldProcedure("d", direction="down")]), SeamProcedure)
    assert s.reverse and s.position == "PG"
    top = select_procedure(TOP, "T", 4.0, [row])  # a horizontal seam: either way, the planner's choice
    assert isinstance(top, SeamProcedure) and not top.reverse and not top.fixed_direction


def test_first_row_that_fits_wins_and_no_fit_is_a_reason() -> None:
    rows = [
        WeldProcedure("pf", position="PF"),
        WeldProcedure("corner", joint="corner"),
        WeldProcedure("big", leg_min_mm=5.0, leg_max_mm=8.0),
    ]
    assert select_procedure(SIDE_DOWN, "T", 4.0, rows).procedure.name == "pf"  # type: ignore[union-attr]
    assert select_procedure(TOP, "corner", 4.0, rows).procedure.name == "corner"  # type: ignore[union-attr]
    assert select_procedure(TOP, "T", 6.0, rows).procedure.name == "big"  # type: ignore[union-attr]
    miss = select_procedure(TOP, "T", 4.0, rows)
    assert isinstance(miss, NoProcedure) and "T joint in position PB with a 4 mm leg" in miss.reason


def test_joint_types_of_fence1() -> None:
    m = read_weldmap(sc.load("fence1"))
    kinds = {sid: joint_type(m, j) for sid, j in find_joints(m).items()}
    assert kinds["BOTTOM_RAIL>POST_L:+y"] == "T"  # the rail's side meets the post mid-face
    assert kinds["BOTTOM_RAIL>POST_L:+z"] == "corner"  # its bottom is flush with the post's: an L in section
    assert set(kinds.values()) == {"T", "corner"}


def test_cross_section_axes() -> None:
    e, b = cross_section(TOP.p_end - TOP.p_start, TOP.n_a, TOP.n_b)
    assert b == pytest.approx(np.array([0.0, -1.0, 1.0]) / math.sqrt(2.0))  # out of the root
    assert e @ TOP.n_b > 0.0 > e @ TOP.n_a  # towards face A (which rises from the root along n_b)
    assert abs(e @ b) < 1e-12 and abs(e @ (TOP.p_end - TOP.p_start)) < 1e-12


def test_weave_width_frequency_and_dwells() -> None:
    v, length = 0.004, 0.08  # [m/s], [m]
    weave = Weave("zigzag", 4.0, 1.0, (0.15, 0.25))
    s = np.linspace(0.0, length, 80001)
    w = weave_lateral(s, length, weave, v)
    assert w[0] == 0.0 and abs(w[-1]) < 1e-12  # on the line at both ends
    mid = (s > 0.02) & (s < 0.06)  # past the fade: the full width
    assert w[mid].max() == pytest.approx(0.002, abs=1e-9) and w[mid].min() == pytest.approx(-0.002, abs=1e-9)
    period = (s > 0.02) & (s <= 0.02 + v / weave.frequency_hz)  # one wavelength v / f = 4 mm
    at_left = np.mean(np.isclose(w[period], 0.002, atol=1e-9))
    at_right = np.mean(np.isclose(w[period], -0.002, atol=1e-9))
    assert at_left == pytest.approx(0.15, abs=0.005) and at_right == pytest.approx(0.25, abs=0.005)
    crossings = np.flatnonzero(np.diff(np.sign(w[mid])) != 0)
    assert len(crossings) == pytest.approx(2 * 0.04 / 0.004, abs=1)  # two per wavelength
    assert not Weave().active and not weave_lateral(s, length, Weave(), v).any()


def test_pass_offsets_and_the_intended_path() -> None:
    d = (TOP.p_end - TOP.p_start) / TOP.length
    e, b = cross_section(d, TOP.n_a, TOP.n_b)
    proc = WeldProcedure("two", passes=(WeldPass(), WeldPass(1.5, 2.5)))
    s = np.linspace(0.0, TOP.length, 7)
    off = pass_offsets(s, TOP.length, proc, 1, e, b)
    assert off == pytest.approx(np.tile(0.0015 * e + 0.0025 * b, (7, 1)))
    assert not pass_offsets(s, TOP.length, proc, 0, e, b).any()
    weaving = WeldProcedure("w", weave=Weave("zigzag", 4.0, 1.0, (0.1, 0.1)))
    p = TOP.p_start + np.outer(s, d)
    p_tcp = p + pass_offsets(s, TOP.length, weaving, 0, e, b)
    back = p_tcp - intended_offsets(p_tcp, TOP.p_start, d, TOP.length, weaving, 0, e, b)
    assert back == pytest.approx(p, abs=1e-12)  # the weave is along e, so its phase is read back exactly
