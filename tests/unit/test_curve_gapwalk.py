"""The reach map's gaps walked finer (cell/planning/curves/gapwalk.py, gapseed.py): the windows joined, the beam's
choice of states (more than one IK branch of a setting), and on the KR 5 arc a tube's foot walked from a window's
middle both ways and a stretch carried on past where it gave out, every step within the knots' flip bound scaled to
the fine stations and every setting within the procedure's tolerance."""

from __future__ import annotations

import math

import numpy as np
from test_curve_reach import OVERLAP_M, _foot, _search
from tiny_cell import HOME

from cell import scenario as sc
from cell.planning.curves.gapseed import seeded
from cell.planning.curves.gapwalk import BEAM, PER_SETTING, State, beam, fine_stations, merged, walked
from cell.planning.curves.graph import graph_map
from cell.planning.curves.path import curve_path, curve_poses
from cell.planning.curves.reach import Run, settings, station_spacing
from cell.planning.curves.search import _flange_axes, knot_spacing
from cell.planning.curves.split import sub_arc


def test_windows_that_overlap_are_joined_round_a_closed_curves_start_too() -> None:
    assert merged([(0.02, 0.05), (0.04, 0.08), (0.1, 0.12)], 0.2, False) == [(0.02, 0.08), (0.1, 0.12)]
    assert merged([(0.01, 0.03), (0.18, 0.215)], 0.2, True) == [(0.18, 0.23)]  # the last runs over the start


def test_the_beam_keeps_more_than_one_ik_branch_of_a_setting_the_fewest_changes_first() -> None:
    z = np.zeros(2)

    def st(v: float, q0: float, changes: int) -> State:
        return State((v, 0.0, 0.0), np.full(6, q0), z, z, z, changes, 0)

    got = beam([st(0.0, 0.0, 2), st(0.0, 1.0, 0), st(0.0, 1.005, 0), st(0.0, 2.0, 1), st(0.1, 0.0, 3)])
    assert [(s.v[0], float(s.q[0]), s.changes) for s in got] == [(0.0, 1.0, 0), (0.0, 2.0, 1), (0.1, 0.0, 3)]
    assert PER_SETTING >= 2  # two branches of one setting kept (the near copy of one dropped), a third not
    many = beam([st(0.01 * k, 0.0, 0) for k in range(3 * BEAM)])
    assert len(many) == BEAM


def _steps_within(search: object, run: Run, bound: float) -> None:
    assert run.track is not None and run.q_track is not None and len(run.track) == len(run.q_track)
    step = np.abs(np.angle(np.exp(1j * np.diff(run.q_track, axis=0))))
    assert float(step.max()) <= bound + 1e-9  # every joint, every fine station
    pr = search.process  # type: ignore[attr-defined]
    assert np.all(np.abs(run.track[:, 2]) <= pr.work_angle_tol + 1e-9)
    assert np.all(np.abs(run.track[:, 3]) <= pr.travel_angle_tol + 1e-9)


def test_a_window_is_walked_from_its_middle_both_ways_and_a_stretch_walked_again_on_through_it() -> None:
    stiff = sc.ProcessSpec(travel_angle_tol_deg=0.0, work_angle_tol_deg=0.0)  # spins only: few settings, quicker
    search, est = _search(spec=stiff), sub_arc(_foot(), 0.0, 0.05, 1)  # 50 mm of the tube's foot, open
    knot = knot_spacing(est, search.opt.spacing)
    fine, bound = fine_stations(search, est, knot)
    assert math.isclose(fine, min(station_spacing(est) / 3.0, knot))
    assert bound <= search.opt.max_joint_step + 1e-12  # the knots' flip bound, not the map's three times it
    probe = curve_path(est, station_spacing(est))
    flange = _flange_axes(search, HOME, curve_poses(probe, search.process)[:, :3, 2])
    window = (0.015, 0.03)
    got = seeded(search, est, [window], flange, HOME, knot, OVERLAP_M)
    assert sorted(r.cand.reversed for r in got) == [False, True]  # a stretch each way
    for run in got:  # back past the window's start (in its weld's sense) by the overlap, on to the arc's end
        if run.cand.reversed:
            assert run.b_m >= window[1] + OVERLAP_M - fine and run.a_m <= fine
        else:
            assert run.a_m <= window[0] - OVERLAP_M + fine and run.b_m >= est.length_m - fine
        _steps_within(search, run, bound)
        assert len(run.track) >= (run.b_m - run.a_m) / fine  # at the fine stations
    # a stretch of the map cut short in the window: walked again from its start and on through it
    runs, _ = graph_map(search, est, settings(search, False), flange, HOME, knot, OVERLAP_M)
    whole = max((r for r in runs if not r.cand.reversed), key=lambda r: r.length)
    assert whole.track is not None and whole.q_track is not None and whole.a_m == 0.0 and whole.b_m > 0.04
    keep = whole.track[:, 0] <= 0.02
    short = Run(whole.cand, whole.a_m, float(whole.track[keep][-1, 0]), whole.q_start, track=whole.track[keep],
                q_track=whole.q_track[keep])  # fmt: skip
    on = walked(search, est, [short], [window], flange, knot, OVERLAP_M)
    assert len(on) == 1 and on[0].a_m == short.a_m and on[0].b_m >= window[1] + OVERLAP_M - fine
    assert np.array_equal(on[0].q_start, short.q_start)
    _steps_within(search, on[0], bound)  # every station of it walked again at the flip bound
