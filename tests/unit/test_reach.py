"""The reach pre-check (cell.planning.reach) on the KR 5 arc: its bounds hold for every reachable pose, a seam beyond
reach is refused before any IK with "beyond reach", a seam inside passes on to IK; the torch test's broad phase
finds the same contacts as querying every box; a gate violation is blamed on the seam whose motion it is in."""

from __future__ import annotations

import numpy as np
import pytest
from tiny_cell import HOME, OBSTACLES, TOP_SEAM, URDF

from cell import scenario as sc
from cell.config.motion import PlanOptions
from cell.gate.base import Violation, ViolationKind
from cell.gate.blame import blamed_seams, incoming, seam_of
from cell.geometry import make_pose
from cell.motion.collision import CollisionChecker
from cell.motion.robot import RobotModel
from cell.planning import seam_search
from cell.planning.plan import reach_model
from cell.planning.reach import ReachModel, seam_reach
from cell.planning.seam_search import SeamSearch
from cell.process.torch import WeldProcess
from cell.types import Box, Part
from cell.types.plan import PlanReason, SeamTask, Segment, WeldPlan
from cell.types.trajectory import Trajectory

PROCESS = WeldProcess.from_spec(sc.ProcessSpec())
TOP = SeamTask(*TOP_SEAM)
# 2.2 m in front of the base: the shoulder-wrist distance (at most 1.23 m) plus the torch cannot get there
FAR = SeamTask(
    "far", np.array([0.0, 2.2, 0.06]), np.array([0.06, 2.2, 0.06]), np.array([0, 0, 1.0]), np.array([0, -1.0, 0])
)
# Measured on this cell: at y = 1.85 m the search still welds this seam, at 1.90 m IK fails for every candidate
# (24 s of restarts without the pre-check); 1.90 m is inside the IK's sum-of-links sphere (2.0 m), out of the cone.
EDGE = SeamTask(
    "edge", np.array([0.0, 1.9, 0.06]), np.array([0.06, 1.9, 0.06]), np.array([0, 0, 1.0]), np.array([0, -1.0, 0])
)


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def reach(robot: RobotModel) -> ReachModel:
    model = reach_model(robot)
    assert model is not None
    return model


def test_the_reach_model_is_the_arms_geometry(reach: ReachModel) -> None:
    # KR 5 arc: A2 0.18 m off A1's axis, 0.4 m up; A2-A3 0.6 m, A3 to the wrist centre hypot(0.12, 0.62) m
    assert reach.radius == pytest.approx(0.18, abs=1e-6)
    assert reach.centre_R[2] + reach.height * reach.axis_R[2] == pytest.approx(0.4, abs=1e-6)
    assert reach.d_max == pytest.approx(0.6 + np.hypot(0.12, 0.62) + 1e-3, abs=1e-6)
    assert 0.3 < reach.d_min < 0.4  # A3's limits keep the wrist centre off the shoulder
    assert np.linalg.norm(reach.p_TW) == pytest.approx(0.488, abs=0.002)  # the wrist centre 0.49 m behind the tip


def test_every_reachable_pose_passes(robot: RobotModel, reach: ReachModel) -> None:
    rng = np.random.default_rng(7)
    lim = robot.limits
    X = np.array([robot.fk(lim.q_min + (lim.q_max - lim.q_min) * rng.random(6)) for _ in range(300)])
    over = reach.pose_excess(X)
    assert over.max() <= 0.0 and over.max() > -0.01  # a necessary condition, and tight: some poses nearly at it
    assert reach.point_excess(X[:, :3, 3]).max() <= 0.0


def test_a_pose_past_the_stretched_arm_fails(robot: RobotModel, reach: ReachModel) -> None:
    # stretch the arm (A3 where the shoulder-wrist distance is largest, A2 level) and push the TCP 5 mm further
    best = max(np.linspace(-0.2, 2.7, 300), key=lambda a3: float(np.linalg.norm(_wrist(robot, a3) - _shoulder(robot))))
    q = np.array([0.0, -0.3, best, 0.0, 0.0, 0.0])
    X = robot.fk(q)
    out = (_wrist(robot, best, q) - _shoulder(robot, q)) / np.linalg.norm(_wrist(robot, best, q) - _shoulder(robot, q))
    assert reach.pose_excess(X)[0] == pytest.approx(-1e-3, abs=2e-3)  # at the bound (its 1 mm pad)
    X[:3, 3] += 0.005 * out
    assert reach.pose_excess(X)[0] == pytest.approx(0.004, abs=0.002)


def _shoulder(robot: RobotModel, q: np.ndarray | None = None) -> np.ndarray:
    return robot.fk(np.zeros(6) if q is None else q, "link_2")[:3, 3]


def _wrist(robot: RobotModel, a3: float, q: np.ndarray | None = None) -> np.ndarray:
    qq = np.zeros(6) if q is None else q.copy()
    qq[2] = a3
    return robot.fk(qq, "link_5")[:3, 3]


def test_a_seam_beyond_reach_is_refused_before_ik(
    robot: RobotModel, reach: ReachModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    def no_ik(*args: object, **kwargs: object) -> None:
        raise AssertionError("IK was tried")

    monkeypatch.setattr(seam_search, "solve_ik", no_ik)
    checker = CollisionChecker(robot, OBSTACLES)
    search = SeamSearch(robot, PROCESS, checker, PlanOptions(), np.random.default_rng(0), reach)
    for task, at_mm in ((FAR, 0.0), (EDGE, 0.0)):
        fail = seam_reach(reach, task, PROCESS)
        assert fail is not None and fail.code is PlanReason.BEYOND_REACH
        assert fail.where.startswith(f"beyond reach: at {at_mm:.1f} mm along the seam")
        out = search.plan_seam(task, HOME)  # no IK, no candidate: the pre-check's failure itself
        assert not isinstance(out, seam_search.SeamSolution)
        assert (out.code, out.where) == (fail.code, fail.where)


def test_a_seam_inside_passes_on_to_ik(robot: RobotModel, reach: ReachModel) -> None:
    assert seam_reach(reach, TOP, PROCESS) is None
    shift = np.array([0.0, 1.8 - TOP.p_start[1], 0.0])  # y = 1.80 m: 100 mm short of EDGE, still weldable
    near = SeamTask("near", TOP.p_start + shift, TOP.p_end + shift, TOP.n_a, TOP.n_b)
    assert seam_reach(reach, near, PROCESS) is None
    checker = CollisionChecker(robot, OBSTACLES[:1])
    search = SeamSearch(robot, PROCESS, checker, PlanOptions(), np.random.default_rng(0), reach)
    assert isinstance(search.plan_seam(near, HOME), seam_search.SeamSolution)


def test_the_torch_tests_broad_phase_finds_what_every_box_finds(robot: RobotModel) -> None:
    import coal

    rng = np.random.default_rng(3)
    boxes = [
        Part(f"B{k}", Box(make_pose(p=rng.uniform([-0.6, 0.4, 0.0], [0.6, 1.2, 0.3])), rng.uniform(0.02, 0.2, 3)))
        for k in range(30)
    ]
    checker = CollisionChecker(robot, boxes)
    shapes = [checker._geom.geometryObjects[i].geometry for i in checker._tool_shapes]
    lim = robot.limits
    hits = 0
    for _ in range(150):
        q = lim.q_min + (lim.q_max - lim.q_min) * rng.random(6)
        X = robot.fk(q)
        X[:3, 3] = rng.uniform([-0.6, 0.4, 0.0], [0.6, 1.2, 0.3])
        got = checker.torch_clear(X, q)
        # brute force: every tool shape against every box
        X_TG = checker._tool.X_TG
        best = np.inf
        for g, X_tg in zip(shapes, X_TG, strict=True):
            X_RG = X @ X_tg
            for k in checker._obstacle_ids:
                obj = checker._geom.geometryObjects[k]
                To = coal.Transform3s(np.array(obj.placement.rotation), np.array(obj.placement.translation))
                d = coal.distance(
                    g,
                    coal.Transform3s(X_RG[:3, :3], X_RG[:3, 3]),
                    obj.geometry,
                    To,
                    coal.DistanceRequest(),
                    coal.DistanceResult(),
                )
                best = min(best, d)
        assert (got is not None) == (best <= 0.0)
        if got is not None:
            hits += 1
            assert got.depth == pytest.approx(best, abs=1e-9)
    assert 20 < hits < 140  # both kinds of pose were tried


def _plan() -> WeldPlan:
    def seg(kind: str, sid: str, t0: float) -> Segment:
        tr = Trajectory(np.array([0.0, 1.0]), np.zeros((2, 6)), np.zeros((2, 6)), np.zeros((2, 6)))
        return Segment(kind, sid, tr, t0, make_pose(p=[0.0, 1.0, 0.1]), arc_on=kind == "weld")  # type: ignore[arg-type]

    kinds = [
        ("move", "a"),
        ("approach", "a"),
        ("weld", "a"),
        ("depart", "a"),
        ("move", "b"),
        ("weld", "b"),
        ("move", ""),
    ]
    segs = tuple(seg(k, s, float(i)) for i, (k, s) in enumerate(kinds))
    return WeldPlan(("a1", "a2", "a3", "a4", "a5", "a6"), np.zeros(6), segs, (), ("a", "b"))


def test_a_gate_violation_is_its_seams() -> None:
    plan = _plan()
    at = {t: seam_of(plan, Violation(ViolationKind.COLLISION, "x", t)) for t in (0.5, 2.5, 4.5, 5.5, 6.5)}
    assert at == {0.5: "a", 2.5: "a", 4.5: "b", 5.5: "b", 6.5: "b"}  # the move home: the last seam's
    assert seam_of(plan, Violation(ViolationKind.START_STATE, "x", 0.0)) == ""
    out = blamed_seams(plan, [Violation(ViolationKind.COLLISION, "torch vs RUNG during the move", 6.5)])
    assert out is not None and list(out) == ["b"]
    assert out["b"].code is PlanReason.TRANSFER_COLLISION and "safety gate" in out["b"].reason
    jerk = blamed_seams(plan, [Violation(ViolationKind.JERK, "too much", 2.5, "a1")])
    assert jerk is not None and jerk["a"].code is PlanReason.TIMING
    assert blamed_seams(plan, [Violation(ViolationKind.START_STATE, "off", 0.0)]) is None  # the whole plan
    both = [Violation(ViolationKind.SINGULARITY, "x", 2.5), Violation(ViolationKind.SINGULARITY, "x", 5.5)]
    assert blamed_seams(plan, both) is None  # every seam at fault: the whole plan is refused
    assert blamed_seams(plan, []) is None


def test_a_violation_on_the_move_into_a_seam_names_that_transfer() -> None:
    """On the move into a seam or its approach (the move blended into it): that transfer, from the seam before or
    home (""), for the gate to try another order; on its weld, or the move home after the last seam: none."""
    plan = _plan()

    def at(*ts: float) -> dict[str, tuple[str, str]]:
        return incoming(plan, [Violation(ViolationKind.SINGULARITY, "x", t) for t in ts])

    assert at(0.5) == at(1.5) == {"a": ("", "a")}
    assert at(4.5) == {"b": ("a", "b")}
    assert at(2.5) == at(3.5) == at(5.5) == at(6.5) == {}
    assert at(4.5, 0.5) == {"b": ("a", "b"), "a": ("", "a")}
    assert at(2.5, 1.5) == {}  # a seam's first violation decides: its weld


def test_the_checks_broad_phase_keeps_every_answer(robot: RobotModel) -> None:
    rng = np.random.default_rng(5)
    boxes = [
        Part(f"B{k}", Box(make_pose(p=rng.uniform([-0.8, 0.3, 0.0], [0.8, 1.3, 0.5])), rng.uniform(0.02, 0.2, 3)))
        for k in range(30)
    ]
    checker = CollisionChecker(robot, boxes)
    lim, mc, step = robot.limits, checker.options.min_clearance, checker.options.max_step
    contacts = 0
    for _ in range(300):
        q = lim.q_min + (lim.q_max - lim.q_min) * rng.random(6)
        d = checker._distances(q)  # every pair queried
        obs, slf = d[checker._pairs.obstacle].min(), d[checker._pairs.self_].min()
        want = 0.0 if d.min() <= mc else min(min(obs, slf / 2.0) - mc, step)
        got, hit = checker._step_bound(q)
        assert (hit is not None) == (d.min() <= mc)
        assert (checker.check(q) is not None) == (d.min() <= mc)
        assert got == pytest.approx(want, abs=2e-6)  # coal's one-pair and all-pair queries differ by < 1 um
        if hit is not None:
            contacts += 1
            assert hit.depth == pytest.approx(d.min(), abs=2e-6)
    assert 30 < contacts < 270
