"""The collision checker's cost on a scenario's designed seams (docs/bodies.md); prints only, writes nothing.

    .venv/bin/python benchmarks/collision_timing.py [--scenario fence1] [--repeat 5] [--meshes]

Plans every visible designed seam (as ``bench_motion.py``'s welding-plan rows: the map in R, no perception), then
times building the checker, the safety gate's collision checks (the gate with the checker minus without) and one
``check(q)`` at random configurations, each the minimum and median over ``--repeat`` runs. ``--meshes`` gives every
part to the checker as a polyhedron (``Box.to_polyhedron``): the cost of the mesh path on the same cell.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from bench_motion import designed_cell

from cell import scenario as sc
from cell.gate import find_violations
from cell.motion.collision import CollisionChecker
from cell.planning.plan import plan_welds
from cell.process.torch import WeldProcess
from cell.types import Part


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="fence1")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--meshes", action="store_true", help="every part as a polyhedron")
    args = parser.parse_args()
    s = sc.load(args.scenario)
    robot, tasks, obstacles = designed_cell(s)
    assert s.robot.home_deg is not None
    if args.meshes:
        obstacles = tuple(
            p if not p.is_box or p.name == "TABLE" else Part(p.name, p.box.to_polyhedron()) for p in obstacles
        )
    home = np.radians(s.robot.home_deg)
    process = WeldProcess.from_spec(s.process, s.robot.stickout_mm)
    plan = plan_welds(robot, tasks, home, process, obstacles, rng=s.rng("plan"))
    checker = CollisionChecker(robot, obstacles)
    rng = np.random.default_rng(0)
    build, gate, check = [], [], []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        CollisionChecker(robot, obstacles)
        build.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        find_violations(robot, plan, home)
        bare = time.perf_counter() - t0
        t0 = time.perf_counter()
        found = find_violations(robot, plan, home, checker=checker)
        gate.append(time.perf_counter() - t0 - bare)
        qs = rng.uniform(-1.0, 1.0, (200, robot.dof))
        t0 = time.perf_counter()
        for q in qs:
            checker.check(q)
        check.append((time.perf_counter() - t0) / len(qs))
    kinds = "meshes" if args.meshes else "as read"
    print(
        f"{args.scenario} ({kinds}, {len(obstacles)} obstacles, {len(tasks)} seams, {len(found)} violations): "
        f"build {min(build) * 1e3:.1f} ms (median {np.median(build) * 1e3:.1f}); "
        f"gate collisions {min(gate):.3f} s (median {np.median(gate):.3f}); "
        f"check(q) {min(check) * 1e6:.0f} us (median {np.median(check) * 1e6:.0f})"
    )


if __name__ == "__main__":
    main()
