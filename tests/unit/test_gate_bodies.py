"""The safety gate's body check: a TCP path (or the wire behind it) that enters a part's body deeper than the
allowed depth is found, with the body's name; one that only sits in a joint's corner is not."""

from __future__ import annotations

from typing import cast

import numpy as np
import numpy.typing as npt
import pytest
from bodies_fixtures import wedge

from cell.gate.bodies import seam_bodies
from cell.geometry import FloatArray, make_pose
from cell.motion.collision.wire import body_entry
from cell.motion.robot import RobotModel
from cell.types import Box, Part, Polyhedron
from cell.types.plan import Segment
from cell.types.trajectory import Trajectory

DEPTH, STEP = 0.001, 0.0005


class _PointRobot:
    """A stand-in arm whose TCP is at q (3,) [m], its torch axis (tool z) along ``z``."""

    def __init__(self, z: npt.ArrayLike = (0.0, 0.0, -1.0)) -> None:
        z = np.asarray(z, dtype=float) / np.linalg.norm(z)
        x = np.cross([0.0, 1.0, 0.0], z) if abs(z[1]) < 0.9 else np.cross([1.0, 0.0, 0.0], z)
        x /= np.linalg.norm(x)
        self.R = np.column_stack([x, np.cross(z, x), z])

    def fk(self, q: npt.ArrayLike) -> FloatArray:
        return make_pose(R=self.R, p=np.asarray(q, dtype=float))


def _line(a: npt.ArrayLike, b: npt.ArrayLike, n: int = 50) -> Trajectory:
    """A straight TCP motion a -> b (3,) [m] over 1 s."""
    t = np.linspace(0.0, 1.0, n)
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    q = a + t[:, None] * (b - a)
    qd = np.tile(b - a, (n, 1))
    return Trajectory(t, q, qd, np.zeros_like(q))


def _entry(tr: Trajectory, bodies: list[Part], wire_m: float = 0.0, z: npt.ArrayLike = (0.0, 0.0, -1.0)) -> object:
    robot = cast(RobotModel, _PointRobot(z))
    return body_entry(robot, tr, bodies, wire_m=wire_m, depth=DEPTH, step=STEP)


def _box(name: str, lo: npt.ArrayLike, hi: npt.ArrayLike) -> Part:
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    return Part(name, Box(make_pose(p=(lo + hi) / 2.0), hi - lo))


def square_tube(half: float, wall: float, y0: float, y1: float) -> Polyhedron:
    """A hollow square tube along y (outer half-width ``half``, wall ``wall``), its axis on x = z = 0 [m]."""
    o, i = half, half - wall
    sq = [(-1, -1), (1, -1), (1, 1), (-1, 1)]  # counter-clockwise seen from -y in (x, z)... as listed below
    v = []
    for y in (y0, y1):
        v += [(o * sx, y, o * sz) for sx, sz in sq]
        v += [(i * sx, y, i * sz) for sx, sz in sq]
    v_arr = np.array(v)
    O0, I0, O1, I1 = 0, 4, 8, 12
    faces = []
    for k in range(4):
        m = (k + 1) % 4
        faces.append((O0 + k, O0 + m, O1 + m, O1 + k))  # outer side
        faces.append((I0 + k, I1 + k, I1 + m, I0 + m))  # inner side, facing the bore
        faces.append((O0 + k, I0 + k, I0 + m, O0 + m))  # the -y end's ring
        faces.append((O1 + k, O1 + m, I1 + m, I1 + k))  # the +y end's ring
    poly = Polyhedron(v_arr, tuple(faces))
    if poly.volume < 0:  # listed the other way round: turn every face
        poly = Polyhedron(v_arr, tuple(tuple(reversed(f)) for f in faces))
    return poly


def test_the_tube_fixture_is_hollow() -> None:
    tube = square_tube(0.03, 0.0026, -0.1, 0.1)
    inside = tube.contains(np.array([[0.0, 0.0, 0.0], [0.0287, 0.0, 0.0], [0.035, 0.0, 0.0]]))
    assert inside.tolist() == [False, True, False]  # the bore, the wall, outside
    assert tube.volume == pytest.approx(4 * 0.2 * (0.03**2 - 0.0274**2), rel=1e-6)


def test_a_path_through_a_box_is_found_with_the_body_and_its_depth() -> None:
    rail = _box("RAIL", [-0.05, -0.5, 0.0], [0.05, 0.5, 0.06])
    hit = _entry(_line([-0.2, 0.0, 0.03], [0.2, 0.0, 0.03]), [rail])
    assert hit is not None
    assert hit.body == "RAIL" and hit.behind_m == 0.0
    assert hit.p_R[0] == pytest.approx(-0.05 + DEPTH, abs=STEP)  # where it first lies deeper than 1 mm
    assert hit.depth >= 0.02  # the rail's middle is 30 mm under its faces


def test_a_weld_running_on_through_a_tube_wall_into_its_bore_is_found() -> None:
    """The arc-off point 8.8 mm inside a tube's bore, behind a 2.6 mm wall: the TCP crosses the wall."""
    tube = Part("TUBE", square_tube(0.03, 0.0026, -0.1, 0.1), "MESH")
    end = [0.03 - 0.0026 - 0.0088, 0.0, 0.0]  # in the bore
    hit = _entry(_line([0.08, 0.0, 0.0], end), [tube])
    assert hit is not None and hit.body == "TUBE"
    assert 0.0274 < hit.p_R[0] < 0.03  # in the wall
    assert not tube.body.contains(np.array(end))  # the end itself is in the bore, outside the body


def test_the_wire_behind_a_tcp_in_the_bore_is_found() -> None:
    """Only the end of the motion is in the bore (the TCP never crosses the wall while moving along the axis), but
    the wire behind it, 15 mm along the torch axis, goes through the wall."""
    tube = Part("TUBE", square_tube(0.03, 0.0026, -0.1, 0.1), "MESH")
    tr = _line([0.02, -0.2, 0.0], [0.02, -0.05, 0.0])  # along the bore, 7.4 mm off its wall: in at the open end
    assert _entry(tr, [tube], wire_m=0.0) is None
    hit = _entry(tr, [tube], wire_m=0.015, z=(-1.0, 0.0, 0.0))  # torch axis along -x: the wire reaches +x of the TCP
    assert hit is not None and hit.body == "TUBE" and 0.0074 < hit.behind_m < 0.01


def test_a_tcp_in_a_joints_corner_is_not_an_entry() -> None:
    """A fillet between a plate and an upright: the TCP runs along their corner 0.3 mm inside both (the seam's
    position error), the wire leaving along the bisector."""
    plate = _box("PLATE", [-0.2, -0.2, -0.01], [0.2, 0.2, 0.0])
    upright = _box("UPRIGHT", [-0.2, -0.01, 0.0], [0.2, 0.0, 0.1])
    tr = _line([-0.1, 0.0003, -0.0003], [0.1, 0.0003, -0.0003])
    assert _entry(tr, [plate, upright], wire_m=0.015, z=(0.0, -1.0, -1.0)) is None
    deeper = _line([-0.1, 0.0, -0.0015], [0.1, 0.0, -0.0015])  # 1.5 mm into the plate
    hit = _entry(deeper, [plate, upright], wire_m=0.015, z=(0.0, -1.0, -1.0))
    assert hit is not None and hit.body == "PLATE"


def test_a_path_through_a_polyhedron_and_one_past_its_corner() -> None:
    block = Part("WEDGE", wedge(length=0.2, base=0.1, height=0.05), "MESH")
    assert _entry(_line([-0.05, 0.0, 0.01], [0.15, 0.0, 0.01]), [block]) is not None
    # along its sloping face, 0.5 mm inside: not deeper than the allowed 1 mm
    n = np.array([0.05, 0.0, 0.1]) / np.linalg.norm([0.05, 0.0, 0.1])
    a, b = np.array([0.0, 0.0, 0.05]), np.array([0.1, 0.0, 0.0])
    assert _entry(_line(a - 0.0005 * n, b - 0.0005 * n), [block]) is None


def test_a_seams_own_parts_are_left_out_along_its_weld_but_not_on_a_transfer() -> None:
    parts = [_box(n, [0, 0, 0], [1, 1, 1]) for n in ("A", "B", "TUBE")]
    tr = _line([0, 0, 0], [1, 0, 0])
    joints = {"A>B": ("A", "B")}
    weld = Segment("weld", "A>B", tr, 0.0, np.eye(4), arc_on=True)
    move = Segment("move", "A>B", tr, 0.0, np.eye(4))
    assert [p.name for p in seam_bodies(parts, weld, joints)] == ["TUBE"]
    assert [p.name for p in seam_bodies(parts, move, joints)] == ["A", "B", "TUBE"]


def test_the_gate_refuses_a_planned_weld_that_runs_into_a_third_part_and_blames_its_seam() -> None:
    """The tiny cell's post-on-rail seams, planned for real: clear of every body (the TCP in its own joint's corner);
    with a third part standing over one end of the top seam, that seam alone is dropped as ``enters_body``."""
    from tiny_cell import HOME, OBSTACLES, POST, RAIL, SIDE_SEAM, TOP_SEAM, URDF

    from cell import scenario as sc
    from cell.gate import ViolationKind, find_violations
    from cell.gate.blame import blamed_seams
    from cell.planning.plan import plan_welds
    from cell.process.torch import WeldProcess
    from cell.types.plan import PlanReason, SeamTask

    robot = RobotModel.from_urdf(URDF)
    process = WeldProcess.from_spec(sc.ProcessSpec())
    plan = plan_welds(robot, [SeamTask(*TOP_SEAM), SeamTask(*SIDE_SEAM)], HOME, process, OBSTACLES)
    assert set(plan.order) == {"top", "side"}
    joints = {"top": ("POST", "RAIL"), "side": ("POST", "RAIL")}
    clear = find_violations(robot, plan, HOME, bodies=(RAIL, POST), wire_m=process.stickout, joint_parts=joints)
    assert clear == []
    tube = _box("TUBE", [-0.036, 0.864, 0.054], [-0.024, 0.876, 0.066])  # 6 mm about the top seam's x = -30 mm end
    found = find_violations(robot, plan, HOME, bodies=(RAIL, POST, tube), wire_m=process.stickout, joint_parts=joints)
    assert found and all(v.kind is ViolationKind.BODY for v in found)
    assert {v.seam_id for v in found} == {"top"} and {v.body for v in found} == {"TUBE"}
    assert found[0].excess >= 0.005  # the arc-off (or -on) point 6 mm inside it
    blamed = blamed_seams(plan, found)
    assert blamed is not None and set(blamed) == {"top"}
    assert blamed["top"].code is PlanReason.ENTERS_BODY and "TUBE" in blamed["top"].reason


def test_a_transfer_the_gate_found_at_fault_is_left_out_of_the_order() -> None:
    """``plan_welds(avoid=...)``: the move from home into the first seam avoided, the two seams are welded the
    other way round (the order goes without it when it can); both still planned."""
    from tiny_cell import HOME, OBSTACLES, SIDE_SEAM, TOP_SEAM, URDF

    from cell import scenario as sc
    from cell.planning.plan import plan_welds
    from cell.process.torch import WeldProcess
    from cell.types.plan import SeamTask

    robot = RobotModel.from_urdf(URDF)
    process = WeldProcess.from_spec(sc.ProcessSpec())
    tasks = [SeamTask(*TOP_SEAM), SeamTask(*SIDE_SEAM)]
    plan = plan_welds(robot, tasks, HOME, process, OBSTACLES)
    again = plan_welds(robot, tasks, HOME, process, OBSTACLES, avoid={("", plan.order[0])})
    assert again.order == plan.order[::-1] and all(o.feasible for o in again.seams)
