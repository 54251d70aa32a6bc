"""Motion primitives benchmark: IK per pose (warm along seams, cold with restarts) and Ruckig timing.

    .venv/bin/python benchmarks/bench_motion.py [--json PATH] [--seed N]

The rows go to ``--json`` (default ``benchmarks/results/motion.json``: ``primitives``, one row per case with a
stable ``key``, and ``plans``, one row per scenario), which ``tools/readme_results.py`` renders into docs/results.md.

Goals: warm-started IK median <= 0.5 ms per pose; ptp computation <= 100 us.
Times are wall-clock per call on this machine (single thread); the table gives median, 90th percentile, max.

Second section, welding plans: every visible seam of each paper scenario's welding map (the designed seams in
the robot frame, no perception: the planner's cost alone) planned by ``plan_welds``, then the safety gate with
and without collision checks: planning time, cycle and arc time, gate times.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from cell.errors import IKError
from cell.export.reports.report import write_json
from cell.geometry import FloatArray, make_pose, rot_y, rot_z
from cell.motion.ik import solve_ik, solve_path
from cell.motion.robot import RobotModel
from cell.motion.timing import path_profile, ptp, ptp_duration

URDF = Path(__file__).resolve().parent.parent / "robots" / "kr5_arc.urdf"
RESULTS = Path(__file__).resolve().parent / "results"
HOME = np.radians([0.0, -90.0, 90.0, 0.0, 0.0, 0.0])


def _timed(fn: Callable[[], object]) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _seams(rng: np.random.Generator, n_seams: int, step: float) -> list[FloatArray]:
    """Torch poses (n, 4, 4) along straight seams 0.1-0.3 m long in front of the robot, every ``step`` [m]."""
    seams = []
    for _ in range(n_seams):
        start = np.array([rng.uniform(0.8, 1.2), rng.uniform(-0.4, 0.4), rng.uniform(-0.3, 0.3)])
        direction = rot_z(rng.uniform(0, 2 * np.pi)) @ np.array([1.0, 0.0, 0.0])
        length = rng.uniform(0.1, 0.3)
        R = rot_z(rng.uniform(-np.pi, np.pi)) @ rot_y(np.pi - rng.uniform(0.3, 0.8))  # wire 17-46 deg off down
        n = int(length / step) + 1
        seams.append(np.array([make_pose(R, start + direction * s) for s in np.linspace(0.0, length, n)]))
    return seams


def _stats(key: str, name: str, seconds: list[float], goal_s: float | None) -> dict[str, object]:
    """One case's times [us]: median, 90th percentile, max, and the goal met (``key`` names the case for readers)."""
    us = np.array(seconds) * 1e6
    row: dict[str, object] = {
        "key": key,
        "case": name,
        "n": len(us),
        "median_us": float(np.median(us)),
        "p90_us": float(np.percentile(us, 90)),
        "max_us": float(np.max(us)),
    }
    if goal_s is not None:
        row["goal_us"] = goal_s * 1e6
        row["ok"] = bool(row["median_us"] <= goal_s * 1e6)  # type: ignore[operator]
    return row


def run(seed: int) -> list[dict[str, object]]:
    rng = np.random.default_rng(seed)
    robot = RobotModel.from_urdf(URDF)
    rows = []

    # Warm-started IK along seams sampled every 2 mm: each pose seeded with the previous solution.
    warm: list[float] = []
    warm_free: list[float] = []
    per_pose_path: list[float] = []
    seams = 0
    for targets in _seams(rng, 20, 0.002):
        if seams == 8:
            break
        try:  # random seams: keep those reachable without a flip
            solve_path(robot, targets, HOME, rng=np.random.default_rng(seed))
        except IKError:
            continue
        seams += 1
        q = solve_ik(robot, targets[0], HOME, rng=np.random.default_rng(seed))
        q_free = q
        for X in targets[1:]:
            t0 = time.perf_counter()
            q = solve_ik(robot, X, q)
            warm.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            q_free = solve_ik(robot, X, q_free, free_axis=True)
            warm_free.append(time.perf_counter() - t0)
        per_pose_path.append(
            _timed(lambda t=targets: solve_path(robot, t, HOME, rng=np.random.default_rng(seed))) / len(targets)
        )
    rows.append(_stats("ik_warm", f"IK warm, full pose ({seams} seams, 2 mm)", warm, 0.5e-3))
    rows.append(_stats("ik_warm_free_axis", "IK warm, free torch axis", warm_free, 0.5e-3))
    rows.append(_stats("solve_path_per_pose", "solve_path, per pose", per_pose_path, 0.5e-3))

    # Cold IK: random reachable poses from the home pose, with seeded restarts.
    cold, failed = [], 0
    while len(cold) < 100:
        q_true = robot.limits.sample(rng, margin=np.radians(10.0))
        if robot.manipulability(q_true) < 0.02:
            continue
        X = robot.fk(q_true)
        t0 = time.perf_counter()
        try:
            solve_ik(robot, X, HOME, rng=np.random.default_rng(seed))
        except IKError:
            failed += 1
        cold.append(time.perf_counter() - t0)
    rows.append(_stats("ik_cold", "IK cold from home, restarts", cold, None))
    rows[-1]["failed"] = failed

    # Ruckig: point-to-point moves between random configurations (rest to rest), sampled at 4 ms.
    lim = robot.limits
    pairs = [(lim.sample(rng), lim.sample(rng)) for _ in range(300)]
    rows.append(
        _stats(
            "ptp_sampled",
            "ptp incl. 4 ms sampling",
            [_timed(lambda a=a, b=b: ptp(a, b, lim)) for a, b in pairs],
            100e-6,
        )
    )
    durations = [ptp(a, b, lim).duration for a, b in pairs[:50]]
    rows[-1]["mean_motion_s"] = float(np.mean(durations))
    rows.append(
        _stats(
            "ptp_duration",
            "ptp_duration (checks + Ruckig solve)",
            [_timed(lambda a=a, b=b: ptp_duration(a, b, lim)) for a, b in pairs],
            100e-6,
        )
    )
    rows.append(
        _stats(
            "path_profile",
            "path_profile 150 mm at 8 mm/s",
            [_timed(lambda: path_profile(0.15, 0.008, 0.5, 5.0)) for _ in range(100)],
            None,
        )
    )
    return rows


def designed_cell(s: Any) -> tuple[RobotModel, list[Any], tuple[Any, ...]]:
    """A scenario's cell as designed, in R, no perception: the arm, a task per visible seam, the obstacles."""
    from cell import scenario as sc
    from cell.geometry import invert
    from cell.motion.collision.scene import cell_obstacles
    from cell.pipeline.detect import table_z_R
    from cell.seams.joint import find_joints, weld_faces
    from cell.seams.visibility import visibility
    from cell.types.plan import SeamTask
    from cell.weldmap import read_map

    assert s.robot.urdf is not None and s.robot.home_deg is not None
    robot = RobotModel.from_urdf(sc.REPO_ROOT / "robots" / s.robot.urdf)
    wm = read_map(s.map_path, units=s.map.units, layers=s.map.layers).transformed(invert(s.X_WR) @ s.X_WM, "R")
    joints = find_joints(wm)
    table_z = table_z_R(s)
    tasks = []
    for seam in wm.seams:
        if visibility(wm, joints[seam.id], table_z)[0]:
            n_a, _, n_b, _ = weld_faces(wm, joints[seam.id])
            tasks.append(SeamTask(seam.id, seam.p_start, seam.p_end, n_a, n_b))
    return robot, tasks, cell_obstacles(wm, s.X_WR, s.table.center_m, s.table.size_m)


def run_plans(names: tuple[str, ...] = ("fence1", "fence2")) -> list[dict[str, object]]:
    """Plan every visible designed seam of each scenario; times [s]."""
    from cell import scenario as sc
    from cell.gate import find_violations
    from cell.motion.collision import CollisionChecker
    from cell.planning.plan import plan_welds
    from cell.process.torch import WeldProcess

    rows: list[dict[str, object]] = []
    for name in names:
        s = sc.load(name)
        robot, tasks, obstacles = designed_cell(s)
        assert s.robot.home_deg is not None
        home = np.radians(s.robot.home_deg)
        process = WeldProcess.from_spec(s.process, s.robot.stickout_mm)
        plan = plan_welds(robot, tasks, home, process, obstacles, rng=s.rng("plan"))
        checker = CollisionChecker(robot, obstacles)
        t0 = time.perf_counter()
        find_violations(robot, plan, home)
        t_gate = time.perf_counter() - t0
        t0 = time.perf_counter()
        found = find_violations(robot, plan, home, checker=checker)
        t_all = time.perf_counter() - t0
        rows.append(
            {
                "scenario": name,
                "seams": len(tasks),
                "planned": sum(o.feasible for o in plan.seams),
                "planning_s": plan.planning_s,
                "cycle_s": plan.cycle_time,
                "arc_s": plan.arc_time,
                "gate_s": t_gate,
                "collision_check_s": t_all - t_gate,
                "violations": len(found),
            }
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, default=RESULTS / "motion.json", help="write the rows to this JSON file")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rows = run(args.seed)
    print(f"{'case':<36} {'n':>5} {'median us':>10} {'p90 us':>9} {'max us':>9} {'goal us':>8}  ok")
    for r in rows:
        goal = f"{r['goal_us']:.0f}" if "goal_us" in r else "-"
        ok = ("yes" if r["ok"] else "NO") if "ok" in r else ""
        print(
            f"{r['case']:<36} {r['n']:>5} {r['median_us']:>10.1f} {r['p90_us']:>9.1f} {r['max_us']:>9.1f} "
            f"{goal:>8}  {ok}"
        )
    plans = run_plans()
    print()
    print(
        f"{'welding plan':<14} {'seams':>5} {'planned':>7} {'plan s':>7} {'cycle s':>8} {'arc s':>7} "
        f"{'gate s':>7} {'collide s':>9} {'viol':>5}"
    )
    for p in plans:
        print(
            f"{p['scenario']:<14} {p['seams']:>5} {p['planned']:>7} {p['planning_s']:>7.2f} {p['cycle_s']:>8.1f} "
            f"{p['arc_s']:>7.1f} {p['gate_s']:>7.2f} {p['collision_check_s']:>9.2f} {p['violations']:>5}"
        )
    print(f"wrote {write_json(args.json, {'primitives': rows, 'plans': plans})}")


if __name__ == "__main__":
    main()
