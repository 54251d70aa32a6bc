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

from cell import scenario as sc
from cell.geometry import invert
from cell.motion.collision import CollisionChecker
from cell.motion.gate import find_violations
from cell.motion.plan import SeamTask, cell_obstacles, plan_welds
from cell.motion.robot import RobotModel
from cell.motion.torch import WeldProcess
from cell.seams.joint import find_joints, weld_faces
from cell.seams.visibility import visibility
from cell.types import Part
from cell.weldmap import read_map


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="fence1")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--meshes", action="store_true", help="every part as a polyhedron")
    args = parser.parse_args()
    s = sc.load(args.scenario)
    assert s.robot.urdf is not None and s.robot.home_deg is not None
    robot = RobotModel.from_urdf(sc.REPO_ROOT / "robots" / s.robot.urdf)
    wm = read_map(s.map_path, units=s.map.units, layers=s.map.layers).transformed(invert(s.X_WR) @ s.X_WM, "R")
    joints = find_joints(wm)
    table_z = float((invert(s.X_WR) @ [0.0, 0.0, s.table.top_z, 1.0])[2])
    tasks = []
    for seam in wm.seams:
        if visibility(wm, joints[seam.id], table_z)[0]:
            n_a, _, n_b, _ = weld_faces(wm, joints[seam.id])
            tasks.append(SeamTask(seam.id, seam.p_start, seam.p_end, n_a, n_b))
    obstacles = cell_obstacles(wm, s.X_WR, s.table.center_m, s.table.size_m)
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
