"""KUKA KRL export (structure a controller needs: INI fold, TOOL/BASE by index, ArcTech's arc statements with
their weld data, S and T), the plain-signal arc mode, and the joint trajectory JSON/CSV export."""

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
from cell.export.status_turn import status_turn
from cell.export.trajectory import write_csv, write_json
from cell.geometry import make_pose, rot_z, rpy_to_matrix
from cell.motion.robot import RobotModel
from cell.planning.plan import plan_welds
from cell.process.torch import WeldProcess
from cell.types import Box, Part
from cell.types.plan import SeamTask, WeldPlan

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
    # every point used in the program is declared, and every declared point is used; XHOME is $config.dat's,
    # XHOME_PLAN the planned home the program compares it with
    used = set(re.findall(r"^(?:PTP|LIN) (\w+)", "\n".join(lines), flags=re.M))
    assert used - {"XHOME"} | {"XHOME_PLAN"} == set(_points(dat))
    assert "XHOME" in used and "XHOME_PLAN." in src


def test_initialisation_precedes_a_fully_defined_first_ptp(robot: RobotModel, plan: WeldPlan) -> None:
    src, dat = krl_program(plan, robot, "W")
    lines = [ln.split(";")[0].strip() for ln in src.splitlines()]
    lines = [ln for ln in lines if ln]
    motions = [i for i, ln in enumerate(lines) if re.match(r"(PTP|LIN|CIRC|SPTP|SLIN) ", ln)]
    first = motions[0]
    before = lines[:first]
    init = [
        "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
        "INTERRUPT ON 3",
        "BAS(#INITMOV, 0)",
        "BAS(#TOOL, 1)",  # TOOL_DATA[1] / LOAD_DATA[1], BASE_DATA[1] by index: values in the setup block
        "BAS(#BASE, 1)",
        "$H_POS = XHOME",
    ]
    assert [ln for ln in before if ln in init] == init  # in this order
    setup = re.findall(r"^;- (TOOL_DATA|LOAD_DATA|BASE_DATA)\[1\] = \{", src, flags=re.M)
    assert setup == ["TOOL_DATA", "LOAD_DATA", "BASE_DATA"]
    assert lines[first] == "PTP XHOME"
    p = _points(dat)["XHOME_PLAN"]
    assert [f"A{i}" for i in range(1, 7)] == [k for k in p if k.startswith("A")]  # all six axes
    np.testing.assert_allclose([p[f"A{i}"] for i in range(1, 7)], np.degrees(HOME), atol=1e-3)  # degrees
    assert lines[-2].startswith("PTP XHOME")  # and back home at the end


def _folds(src: str) -> list[tuple[str, str, str, list[str]]]:
    """ArcTech inline forms of a .src: (ARCON | ARCSWI | ARCOFF, weld data set, seam id, the fold's code lines)."""
    out: list[tuple[str, str, str, list[str]]] = []
    body: list[str] = []
    head: tuple[str, str, str] | None = None
    seam = ""
    for ln in (ln.strip() for ln in src.splitlines()):
        m = re.match(r";FOLD (ARCON|ARCSWI|ARCOFF) (\w+) ", ln)
        if (c := re.match(r";- ARC_(?:ON|SWI|OFF) seam (\S+) ", ln)) is not None:
            seam = c.group(1)  # the comment line before each inline form names its seam
        elif m is not None:
            head, body = (m.group(1), m.group(2), seam), []
        elif head is not None and ln == ";ENDFOLD" and body and body[-1].startswith("ArcMainNG(#Arc"):
            out.append((head[0], head[1], head[2], body))
            head = None
        elif head is not None and not ln.startswith(";"):
            body.append(ln)
    return out


def _decl(dat: str, name: str) -> str:
    return next(ln for ln in dat.splitlines() if ln.startswith("DECL ") and f" {name}=" in ln)


def test_each_weld_is_arc_on_then_off_with_declared_weld_data(robot: RobotModel, plan: WeldPlan) -> None:
    X_RB = make_pose(rot_z(0.4), [0.05, 0.8, 0.01])  # the part's base: every LIN point is written in it
    src, dat = krl_program(plan, robot, "W", X_RB=X_RB)
    folds = _folds(src)
    assert [(f[0], f[2]) for f in folds] == [(k, s) for s in plan.order for k in ("ARCON", "ARCOFF")]
    assert sorted(plan.order) == ["side", "top"]
    pts = _points(dat)
    for (on, wd_on, seam_id, body_on), (off, wd_off, _, body_off) in zip(folds[::2], folds[1::2], strict=True):
        for kind, wdat, body in ((on, wd_on, body_on), (off, wd_off, body_off)):
            motions = [ln for ln in body if re.match(r"(PTP|LIN) ", ln)]
            assert len(motions) == 1 and "C_DIS" not in motions[0]  # one motion, an exact stop
            step = "ArcOn" if kind == "ARCON" else "ArcOff"
            assert body[-3] == f"ArcMainNG(#{step}BeforeMoveStd, {wdat}, W{motions[0].split()[1][1:]})"
            assert body[-1].startswith(f"ArcMainNG(#{step}AfterMoveStd, {wdat},")
        # ARC_ON's data set: ignition and the weld's path velocity (the process' travel speed, m/s); ARC_OFF's:
        # the crater
        d_on, d_off = _decl(dat, wd_on), _decl(dat, wd_off)
        assert d_on.startswith(f"DECL stArcDat_T {wd_on}=") and "Strike {" in d_on and "Weave {" in d_on
        vel = re.search(r"Weld \{[^}]*Velocity " + NUM, d_on)
        assert vel is not None
        v = float(vel.group(1))
        assert v == pytest.approx(PROCESS.travel_speed, abs=1e-5)
        assert "Crater {" in d_off and "CraterTime 0.300" in d_off
        # the weld runs from ARC_ON's point (the ignition) to ARC_OFF's, the seam's ends, in the base
        start, end = (pts[next(ln for ln in b if ln.startswith("LIN ")).split()[1]] for b in (body_on, body_off))
        task = next(t for t in SEAMS if t.id == seam_id)
        got = [X_RB @ np.array([p["X"], p["Y"], p["Z"], 1000.0]) for p in (start, end)]
        want = [np.append(p * 1000.0, 1000.0) for p in (task.p_start, task.p_end)]
        np.testing.assert_allclose(sorted(map(tuple, got)), sorted(map(tuple, want)), atol=0.01)
    for p in pts.values():  # plausible units: mm within the arm's reach, angles in degrees
        if "X" in p:
            assert np.linalg.norm([p["X"], p["Y"], p["Z"]]) < 2000.0
            assert all(-180.0 <= p[k] <= 180.0 for k in "ABC")


def test_every_e6pos_has_the_status_and_turn_of_its_planned_configuration(robot: RobotModel, plan: WeldPlan) -> None:
    _, dat = krl_program(plan, robot, "W")
    pts = _points(dat)
    lins = [s for s in plan.segments if s.kind != "move"]
    e6pos = [name for name in pts if "S" in pts[name]]
    assert len(e6pos) == len(lins) and all("T" in pts[n] for n in e6pos)
    for name, seg in zip(sorted(e6pos, key=lambda n: int(n[2:])), lins, strict=True):
        assert (pts[name]["S"], pts[name]["T"]) == status_turn(robot, seg.q_end)


def test_blended_motions_are_approximated_by_their_zone_to_their_programmed_point(
    robot: RobotModel, plan: WeldPlan
) -> None:
    from cell.export.program import ProgramJob
    from cell.export.rapid import rapid_text

    blended = [s for s in plan.segments if s.zone_m > 0.0]
    assert blended and all(s.q_target is not None and not s.arc_on for s in blended)
    src, dat = krl_program(plan, robot, "W")
    zones = [float(z) for z in re.findall(r"\$APO\.CDIS = " + NUM, src)]
    c_dis = [ln for ln in src.splitlines() if " C_DIS" in ln]
    assert len(c_dis) == len(blended) and len(zones) >= 1
    assert {round(s.zone_m * 1000.0, 1) for s in blended} == set(zones)
    pts = _points(dat)
    for ln, seg in zip(c_dis, blended, strict=True):
        name = ln.split()[1]
        if seg.kind == "move":  # the E6AXIS is the programmed point, not where the blend leaves the move
            got = np.radians([pts[name][f"A{i}"] for i in range(1, 7)])
            np.testing.assert_allclose(got, seg.q_end, atol=np.radians(0.001))  # written to 0.001 deg
            assert not np.allclose(seg.q_end, seg.trajectory.q[-1], atol=1e-6)
    mod = rapid_text(ProgramJob(plan, robot, "W"))
    assert len(re.findall(r", zB[0-9_]+, tWeld", mod)) == len(blended)
    assert "CONST zonedata zB" in mod


def test_abc_are_rotations_about_z_y_x_with_x_along_the_wire(robot: RobotModel, plan: WeldPlan) -> None:
    src, dat = krl_program(plan, robot, "W")
    pts = _points(dat)
    weld = next(s for s in plan.segments if s.kind == "weld")
    off = next(f for f in _folds(src) if f[0] == "ARCOFF" and f[2] == weld.seam_id)
    p = pts[next(ln for ln in off[3] if ln.startswith("LIN ")).split()[1]]
    R = rpy_to_matrix(np.radians([p["C"], p["B"], p["A"]]))  # Rz(A) Ry(B) Rx(C)
    np.testing.assert_allclose(R[:, 0], weld.X_end[:3, 2], atol=1e-4)  # KUKA tool direction X = the wire
    m = re.search(r"TOOL_DATA\[1\] = \{X " + NUM + ", Y " + NUM + ", Z " + NUM, src)
    assert m is not None
    X_FT = np.linalg.inv(robot.fk(HOME, "tool0")) @ robot.fk(HOME, "torch_tcp")
    np.testing.assert_allclose([float(v) for v in m.groups()], X_FT[:3, 3] * 1000.0, atol=1e-3)


def test_plain_signal_arc_waits_for_the_arc_with_a_timeout_and_bad_names(robot: RobotModel, plan: WeldPlan) -> None:
    opt = KrlOptions(arc="signals", arc_on_output=7, arc_ok_input=9, arc_timeout_s=1.5)
    src, _ = krl_program(plan, robot, "W", options=opt)
    code = [ln.split(";")[0].strip() for ln in src.splitlines()]
    code = [ln for ln in code if ln]
    assert "ArcMainNG" not in src and code.count("$OUT[7] = TRUE") == 2 and code.count("$OUT[7] = FALSE") == 4
    for i in (k for k, ln in enumerate(code) if ln == "$OUT[7] = TRUE"):
        block = code[i : i + 12]
        assert block[1:7] == [
            "$TIMER_STOP[1] = TRUE", "$TIMER[1] = -1500", "$TIMER_STOP[1] = FALSE",
            "WAIT FOR $IN[9] OR $TIMER_FLAG[1]", "$TIMER_STOP[1] = TRUE", "IF NOT $IN[9] THEN",
        ]  # fmt: skip
        assert block[7:10] == ["$OUT[7] = FALSE", "HALT", "ENDIF"]  # the error branch: arc off, stop
        weld = next(k for k in range(i, len(code)) if code[k].startswith("LIN "))
        assert code[weld - 1] == f"$VEL.CP = {PROCESS.travel_speed:.4f}"
        assert code[weld + 1 : weld + 3] == ["WAIT SEC 0.300", "$OUT[7] = FALSE"]  # crater, then arc off
    for bad in ("1WELD", "WELD-1", "", "A" * 25):
        with pytest.raises(ValueError, match="program name"):
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


def test_trajectory_files_are_written_whole(plan: WeldPlan, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import errno
    import os
    import stat
    from typing import Any

    from cell.errors import OutputError, OutputFault
    from cell.outputs import leftovers

    path = write_csv(plan, tmp_path / "trajectory_A.csv")
    whole = path.read_bytes()
    savetxt = np.savetxt

    def disk_full(fname: str, rows: np.ndarray, **options: Any) -> None:  # half the rows, then no space
        savetxt(fname, rows[: len(rows) // 2], **options)
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(np, "savetxt", disk_full)
    with pytest.raises(OutputError) as e:
        write_csv(plan, path)
    assert e.value.code is OutputFault.WRITE_FAILED and "trajectory" in e.value.message
    assert path.read_bytes() == whole and leftovers(tmp_path) == []  # never cut at a line boundary
    fifo = tmp_path / "trajectory_A.json"
    os.mkfifo(fifo)
    with pytest.raises(OutputError) as e:
        write_json(plan, fifo)
    assert e.value.code is OutputFault.FIFO and stat.S_ISFIFO(os.lstat(fifo).st_mode)
