"""The reach map as a graph (cell/planning/curves/graph.py), on small made-up maps: which settings a path may turn
to, a path that turns from one setting to a neighbouring one to pass where neither holds all the way, the torch's
settings interpolated along an arc, and the gaps walked again with finer settings. No IK here (the graph's nodes
are given)."""

from __future__ import annotations

import math

import numpy as np
from tiny_cell import TABLE, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning.curves.arc_solve import same_stretch
from cell.planning.curves.graph import _neighbours, _paths, _runs, gaps, settings_along
from cell.planning.curves.reach import Run
from cell.planning.plan import reach_model
from cell.planning.seam_search import SeamSearch
from cell.process.torch import WeldProcess
from cell.process.torch_orientations import Candidate

W, T = math.radians(10.0), math.radians(10.0)
SPIN = 2.0 * math.pi / 8


def _search() -> SeamSearch:
    robot = RobotModel.from_urdf(URDF)
    opt = PlanOptions()
    process = WeldProcess.from_spec(sc.ProcessSpec())
    return SeamSearch(robot, process, CollisionChecker(robot, (TABLE,), opt.collision), opt,
                      np.random.default_rng(0), reach_model(robot))  # fmt: skip


def test_a_path_turns_the_spin_one_step_or_tilts_within_the_tolerance_never_both_nor_across_directions() -> None:
    cands = [Candidate(False, 0.0, 0.0, 0.0), Candidate(False, SPIN, 0.0, 0.0), Candidate(False, 2 * SPIN, 0.0, 0.0),
             Candidate(False, 0.0, W, 0.0), Candidate(False, SPIN, W, 0.0), Candidate(False, 0.0, -W, 0.0),
             Candidate(True, 0.0, 0.0, 0.0), Candidate(False, math.pi, 0.0, 0.0)]  # fmt: skip
    nb = _neighbours(cands, True, W, T)
    assert sorted(nb[0]) == [1, 3, 5]  # one spin step, or the work angle to either end of its tolerance
    assert sorted(nb[3]) == [0, 4]  # not from one end of the tolerance to the other at once
    assert 4 not in nb[0] and 6 not in nb[0]  # not spun and tilted at once; never the other direction
    assert nb[7] == []  # half a turn away
    assert 7 in _neighbours([*cands, Candidate(False, -3 * SPIN, 0.0, 0.0)], True, W, T)[8]  # round through pi


def test_a_path_turns_to_a_neighbouring_setting_where_its_own_gives_out() -> None:
    search = _search()
    q = np.radians([-90.0, -100.0, 100.0, 0.0, 45.0, 0.0])
    n = 12
    held_a = [q + 0.01 * k if k <= 6 else None for k in range(n)]  # spin 0 holds stations 0-6
    held_b = [q + 0.01 * k + 0.05 if k >= 4 else None for k in range(n)]  # spin one step on holds 4-11
    cands = [Candidate(False, 0.0, 0.0, 0.0), Candidate(False, SPIN, 0.0, 0.0)]
    poses = [np.zeros((n, 4, 4))] * 2
    nodes = _paths(search, poses, [held_a, held_b], _neighbours(cands, True, W, T), False, n, math.radians(60.0),
                   np.zeros(n, dtype=bool))  # fmt: skip
    runs = _runs(nodes, cands, 0.01, 0.11, False, False, n)
    assert len(runs) == 1 and runs[0].a_m == 0.0 and math.isclose(runs[0].b_m, 0.11)
    spin, _, _ = settings_along(runs[0], np.array([0.0, 0.05, 0.11]))
    assert spin[0] == 0.0 and math.isclose(spin[-1], SPIN)  # turned once, somewhere on the way
    far = [q + 2.0 if x is not None else None for x in held_b]  # the other wrist: not a turn, a flip
    nodes = _paths(search, poses, [held_a, far], _neighbours(cands, True, W, T), False, n, math.radians(60.0),
                   np.zeros(n, dtype=bool))  # fmt: skip
    spans = sorted((r.a_m, r.b_m) for r in _runs(nodes, cands, 0.01, 0.11, False, False, n))
    assert spans == [(0.0, 0.06), (0.04, 0.11)]


def test_the_settings_along_an_arc_pass_through_its_stations_smoothly_and_follow_it_a_lap_on() -> None:
    track = np.array([[0.00, 0.0, 0.0, 0.0], [0.01, 0.0, 0.0, 0.0], [0.03, SPIN, 0.0, 0.0], [0.04, SPIN, W, 0.0]])
    run = Run(Candidate(False, 0.0, 0.0, 0.0), 0.0, 0.04, np.zeros(6), track=track)
    x = np.linspace(0.0, 0.04, 41)
    spin, work, _ = settings_along(run, x)
    assert np.all(np.diff(spin) >= -1e-12) and spin.max() <= SPIN + 1e-12  # no overshoot
    assert math.isclose(spin[20], 0.5 * SPIN, abs_tol=1e-9) and work[30] == 0.0
    lap = Run(run.cand, 1.0, 1.04, run.q_start, track=track, origin_m=1.0)  # the same arc a lap on
    assert np.allclose(settings_along(lap, x + 1.0)[0], spin)
    still = settings_along(Run(Candidate(False, 0.3, 0.0, W), 0.0, 0.04, np.zeros(6)), x)
    assert np.all(still[0] == 0.3) and np.all(still[2] == W)


def test_the_gaps_of_a_map_widened_either_side_one_across_a_loops_start() -> None:
    run = Run(Candidate(False, 0.0, 0.0, 0.0), 0.1, 0.9, np.zeros(6))
    got = gaps([run], 1.0, True, 0.02)
    assert len(got) == 1 and math.isclose(got[0][0], 0.88) and math.isclose(got[0][1] - 1.0, 0.12)
    assert gaps([run], 0.9, False, 0.0) == [(0.0, 0.1)]
    assert gaps([Run(run.cand, 0.0, 1.0, np.zeros(6))], 1.0, True, 0.02) == []


def test_every_setting_that_reaches_furthest_from_a_start_is_kept_for_the_cover_to_fall_back_on() -> None:
    search = _search()
    q = np.radians([-90.0, -100.0, 100.0, 0.0, 45.0, 0.0])
    n = 10
    held = [q + 0.01 * k for k in range(n)]
    cands = [Candidate(False, 0.0, 0.0, 0.0), Candidate(False, SPIN, 0.0, 0.0)]  # both hold every station
    poses = [np.zeros((n, 4, 4))] * 2
    nodes = _paths(search, poses, [held, [x + 0.05 for x in held]], _neighbours(cands, True, W, T), False, n,
                   math.radians(60.0), np.zeros(n, dtype=bool))  # fmt: skip
    runs = [r for r in _runs(nodes, cands, 0.01, 0.09, False, False, n) if r.a_m == 0.0]
    assert len(runs) == 2 and all(math.isclose(r.b_m, 0.09) for r in runs)  # a second whole path if one fails
    assert [r.spare for r in runs] == [False, True]  # tried only once no cover of the first ones welds
    assert not same_stretch(runs[0], runs[1], 0.09) and same_stretch(runs[0], runs[0], 0.09)
