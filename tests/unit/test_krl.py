"""KUKA KRL export (structure a controller needs) and the joint trajectory JSON/CSV export."""

from __future__ import annotations

import csv
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from cell import scenario as sc
from cell.export.krl import KrlOptions, krl_program, write_krl
from cell.export.trajectory import write_csv, write_json
from cell.geometry import make_pose, rpy_to_matrix
from cell.motion.plan import SeamTask, WeldPlan, plan_welds
from cell.motion.robot import RobotModel
from cell.motion.torch import WeldProcess
from cell.types import Box, Part

URDF = Path(__file__).resolve().parents[2] / "robots" / "kr5_arc.urdf"
HOME = np.radians([-90.0, -100.0, 100.0, 0.0, 45.0, 0.0])
OBSTACLES = (
    Part("TABLE", Box(make_pose(p=[0.0, 1.05, -0.05]), np.array([2.0, 1.2, 0.1]))),
    Part("RAIL", Box(make_pose(p=[0.0, 0.92, 0.03]), np.array([0.4, 0.1, 0.06]))),
    Part("POST", Box(make_pose(p=[0.0, 0.769, 0.03]), np.array([0.06, 0.2, 0.06]))),
)
SEAMS = (
    SeamTask(
        "top",
        np.array([-0.03, 0.87, 0.06]),
        np.array([0.03, 0.87, 0.06]),
        np.array([0, 0, 1.0]),
        np.array([0, -1.0, 0]),
    ),
    SeamTask(
        "side", np.array([0.03, 0.87, 0.0]), np.array([0.03, 0.87, 0.06]), np.array([1.0, 0, 0]), np.array([0, -1.0, 0])
    ),
)
PROCESS = WeldProcess.from_spec(sc.ProcessSpec())
NUM = r"(-?\d+(?:\.\d+)?)"


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.from_urdf(URDF)


@pytest.fixture(scope="module")
def plan(robot: RobotModel) -> WeldPlan:
    p = plan_welds(robot, SEAMS, HOME, PROCESS, OBSTACLES)
    assert all(o.feasible for o in p.seams)
    return p


def _points(dat: str) -> dict[str, dict[str, float]]:
    """DECL lines of a .dat: point name -> {component: value}."""
    out = {}
    for name, body in re.findall(r"DECL E6(?:POS|AXIS) (\w+)=\{([^}]*)\}", dat):
        out[name] = {k: float(v) for k, v in re.findall(r"(\w+) " + NUM, body)}
    return out


def test_files_have_matching_names_and_blocks(robot: RobotModel, plan: WeldPlan, tmp_path: Path) -> None:
    src_path, dat_path = write_krl(plan, robot, tmp_path, "fence_weld", X_WR=make_pose(p=[0.15, -1.05, 0.9]))
    assert (src_path.name, dat_path.name) == ("FENCE_WELD.src", "FENCE_WELD.dat")
    src = src_path.read_bytes().decode("ascii")
    dat = dat_path.read_bytes().decode("ascii")
    assert "\r\n" in src  # controller line ends
    lines = [ln.strip() for ln in src.splitlines() if ln.strip()]
    defs = [ln for ln in lines if ln.startswith("DEF ")]
    assert defs == [f"DEF {src_path.stem}( )"]
    assert lines[-1] == "END"
    dlines = [ln.strip() for ln in dat.splitlines() if ln.strip()]
    assert dlines[0] == f"DEFDAT {dat_path.stem} PUBLIC" and dlines[-1] == "ENDDAT"
    # every point used in the program is declared, and every declared point is used
    used = set(re.findall(r"^(?:PTP|LIN) (\w+)", "\n".join(lines), flags=re.M))
    assert used == set(_points(dat))


def test_initialisation_precedes_a_fully_defined_first_ptp(robot: RobotModel, plan: WeldPlan) -> None:
    src, dat = krl_program(plan, robot, "W")
    lines = [ln.split(";")[0].strip() for ln in src.splitlines()]
    lines = [ln for ln in lines if ln]
    motions = [i for i, ln in enumerate(lines) if re.match(r"(PTP|LIN|CIRC|SPTP|SLIN) ", ln)]
    first = motions[0]
    before = lines[:first]
    assert "BAS(#INITMOV, 0)" in before
    for var in ("$TOOL = ", "$BASE = ", "$LOAD = "):
        assert any(ln.startswith(var) for ln in before), var
    assert lines[first].startswith("PTP ")
    p = _points(dat)[lines[first].split()[1]]
    assert [f"A{i}" for i in range(1, 7)] == [k for k in p if k.startswith("A")]  # all six axes
    np.testing.assert_allclose([p[f"A{i}"] for i in range(1, 7)], np.degrees(HOME), atol=1e-3)  # degrees
    assert lines[-2].startswith("PTP XHOME")  # and back home at the end


def test_welds_are_lin_at_weld_speed_between_arc_markers(robot: RobotModel, plan: WeldPlan) -> None:
    src, dat = krl_program(plan, robot, "W")
    lines = [ln.strip() for ln in src.splitlines() if ln.strip()]
    on = [i for i, ln in enumerate(lines) if ln.startswith(";ARC_ON")]
    off = [i for i, ln in enumerate(lines) if ln.startswith(";ARC_OFF")]
    assert len(on) == len(off) == 2
    pts = _points(dat)
    for i, k in zip(on, off, strict=True):
        assert k == i + 2 and lines[i + 1].startswith("LIN ")  # exactly one weld motion between the markers
        vel = [ln for ln in lines[:i] if ln.startswith("$VEL.CP")][-1]
        assert float(vel.split("=")[1].split(";")[0]) == pytest.approx(PROCESS.travel_speed)  # m/s
        before = [ln for ln in lines[:i] if re.match(r"(PTP|LIN) ", ln)][-1]
        assert before.startswith("LIN ") and "C_DIS" not in before and "C_VEL" not in before  # exact stop
        seam_id = lines[i].split()[-1]
        task = next(t for t in SEAMS if t.id == seam_id)
        start, end = (pts[ln.split()[1]] for ln in (before, lines[i + 1]))
        xyz = [np.array([p["X"], p["Y"], p["Z"]]) for p in (start, end)]
        # millimetres: the weld end points are the seam's end points x 1000
        got = sorted([tuple(np.round(x, 1)) for x in xyz])
        want = sorted([tuple(np.round(p * 1000.0, 1)) for p in (task.p_start, task.p_end)])
        np.testing.assert_allclose(got, want, atol=0.05)
    for p in pts.values():  # plausible units: mm within the arm's reach, angles in degrees
        if "X" in p:
            assert np.linalg.norm([p["X"], p["Y"], p["Z"]]) < 2000.0
            assert all(-180.0 <= p[k] <= 180.0 for k in "ABC")


def test_abc_are_rotations_about_z_y_x_with_x_along_the_wire(robot: RobotModel, plan: WeldPlan) -> None:
    src, dat = krl_program(plan, robot, "W")
    pts = _points(dat)
    weld = next(s for s in plan.segments if s.kind == "weld")
    i = [ln.strip() for ln in src.splitlines()].index(f";ARC_OFF seam {weld.seam_id}")
    name = [ln.strip() for ln in src.splitlines()][i - 1].split()[1]
    p = pts[name]
    R = rpy_to_matrix(np.radians([p["C"], p["B"], p["A"]]))  # Rz(A) Ry(B) Rx(C)
    np.testing.assert_allclose(R[:, 0], weld.X_end[:3, 2], atol=1e-4)  # KUKA tool direction X = the wire
    m = re.search(r"\$TOOL = \{X " + NUM + ", Y " + NUM + ", Z " + NUM, src)
    assert m is not None
    X_FT = np.linalg.inv(robot.fk(HOME, "tool0")) @ robot.fk(HOME, "torch_tcp")
    np.testing.assert_allclose([float(v) for v in m.groups()], X_FT[:3, 3] * 1000.0, atol=1e-3)


def test_call_markers_and_bad_names(robot: RobotModel, plan: WeldPlan) -> None:
    src, _ = krl_program(plan, robot, "W", options=KrlOptions(arc_markers="call"))
    calls = [ln.split(";")[0].strip() for ln in src.splitlines() if ln.startswith("WELD_ARC_")]
    assert calls == ["WELD_ARC_ON( )", "WELD_ARC_OFF( )"] * 2
    for bad in ("1WELD", "WELD-1", "", "A" * 25):
        with pytest.raises(ValueError, match="KRL program name"):
            krl_program(plan, robot, bad)


def test_joint_trajectory_json_and_csv(plan: WeldPlan, tmp_path: Path) -> None:
    msg = json.loads(write_json(plan, tmp_path / "t.json").read_text())
    assert msg["joint_names"] == [f"joint_a{i}" for i in range(1, 7)]
    pts = msg["points"]
    t = np.array([p["time_from_start"]["sec"] + p["time_from_start"]["nanosec"] * 1e-9 for p in pts])
    assert t[0] == 0.0 and np.all(np.diff(t) > 0.0) and t[-1] == pytest.approx(plan.cycle_time, abs=1e-6)
    assert all(0 <= p["time_from_start"]["nanosec"] < 1_000_000_000 for p in pts)
    assert all(len(p["positions"]) == len(p["velocities"]) == len(p["accelerations"]) == 6 for p in pts)
    np.testing.assert_allclose(pts[0]["positions"], HOME, atol=1e-9)
    with (write_csv(plan, tmp_path / "t.csv")).open() as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["t_s", *[f"q{i}_rad" for i in range(1, 7)], "arc_on"]
    arc = np.array([int(r[-1]) for r in rows[1:]])
    times = np.array([float(r[0]) for r in rows[1:]])
    assert int(np.sum(np.diff(arc) == 1)) == 2  # two welds: the arc switches on twice
    on_time = float(np.sum(np.diff(times)[arc[:-1] == 1]))
    assert on_time == pytest.approx(plan.arc_time, abs=2e-6)
    assert math.isclose(times[-1], plan.cycle_time, abs_tol=1e-5)
