"""ABB RAPID export of a welding plan (docs/reference.md section 5): one module ``NAME.mod`` (RobotWare Arc).

The module: a header (what made it), ``tooldata`` (the torch TCP in the flange, z along the wire: ABB's tool
direction), ``wobjdata`` (the part's base: the aligned map, in the user frame, so one frame moves every seam),
``speeddata`` of the plan's speeds, per weld procedure ``seamdata`` (pre-flow, ignition, crater fill,
burn-back, post-flow), ``welddata`` (weld speed and the main arc: voltage, wire feed, current) and
``weavedata``, every point declared (``jointtarget`` home, ``robtarget`` with ``confdata``), and ``PROC main``:
``MoveAbsJ`` home, per seam ``MoveJ`` transfers, ``ArcLStart`` on the approach (ignition at the weld start),
``ArcL`` on every weld motion followed by another of the same arc, ``ArcLEnd`` on the last, ``MoveL`` departs,
``MoveAbsJ`` home. With a linear track (docs/track.md) its position is every point's ``eax_a`` [mm]. Every point is
an exact stop (``fine``); ``ConfJ \\On`` / ``ConfL \\On`` make the controller
refuse a configuration other than the one written.

confdata [cf1, cf4, cf6, cfx]: the quarter turns of axes 1, 4 and 6 (floor of the angle / 90 deg) and the
configuration cfx = 4 (wrist centre behind axis 1) + 2 (behind the lower arm's line) + 1 (axis 5 negative),
from the plan's joint values on its arm (the same geometry as KUKA's Status, :mod:`cell.export.status_turn`).
The data types' component lists follow RobotWare Arc's ``arcdata`` [sched, mode, voltage, wirefeed, control,
current, voltage2, wirefeed2, control2]; the components a power source uses depend on its configuration.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from cell.export.program import ProgramJob, procedure_of
from cell.export.status_turn import A1_FRAME, A2_FRAME, A3_FRAME, WRIST_FRAME
from cell.geometry import FloatArray, invert
from cell.provenance import header_lines
from cell.types.plan import Segment
from cell.types.procedure import WeavePattern, WeldProcedure
from cell.types.robot import Kinematics

# ABB weavedata.weave_shape: 1 is the sideways (horizontal) zigzag, a triangle wave across the seam, which is what
# both our zigzag and our triangle are (ABB's 2 and 3, V-shaped and triangular, rise out of the seam's plane: none of
# ours); 4 is ABB's circular weave (docs/reference.md section 5).
_SHAPE: dict[WeavePattern, int] = {"none": 0, "zigzag": 1, "triangle": 1, "circle": 4}
_EXT = "[9E9,9E9,9E9,9E9,9E9,9E9]"


def extax(e1: float | None) -> str:
    """``extjoint`` of a point: eax_a the linear track's E1 [m] (written in mm, as RAPID gives a linear axis),
    the others unused (9E9); all unused without a track (None)."""
    return _EXT if e1 is None else f"[{_n(e1 * 1000.0)},9E9,9E9,9E9,9E9,9E9]"


def _n(v: float, digits: int = 3) -> str:
    s = f"{v:.{digits}f}"
    return s[1:] if s.startswith("-") and float(s) == 0.0 else s


def pose_text(X: FloatArray) -> str:
    """``[[x, y, z], [q1, q2, q3, q4]]`` of a pose (4, 4) [m]: mm and a unit quaternion (scalar first, q1 >= 0)."""
    x, y, z, w = Rotation.from_matrix(np.asarray(X)[:3, :3]).as_quat()
    q = np.array([w, x, y, z]) * (1.0 if w >= 0.0 else -1.0)
    p = np.asarray(X)[:3, 3] * 1000.0
    return f"[[{','.join(_n(v) for v in p)}],[{','.join(_n(v, 6) for v in q)}]]"


def confdata(r: Kinematics, q: FloatArray) -> str:
    """``[cf1, cf4, cf6, cfx]`` of the configuration q (6,) [rad] of the arm r (module docstring)."""
    quarter = [math.floor(math.degrees(q[i]) / 90.0 + 1e-9) for i in (0, 3, 5)]
    X_RA1 = r.fk(q, A1_FRAME)
    p_w, p2, p3 = (invert(X_RA1) @ np.append(r.fk(q, f)[:3, 3], 1.0) for f in (WRIST_FRAME, A2_FRAME, A3_FRAME))
    u = (p3 - p2)[:3]
    front = np.array([u[2], 0.0, -u[0]])  # the lower arm's forward normal in the arm plane (A1 frame: x fwd, z up)
    cfx = 4 * int(p_w[0] < 0.0) + 2 * int(float(np.dot((p_w - p2)[:3], front)) < 0.0) + int(q[4] < 0.0)
    return f"[{quarter[0]},{quarter[1]},{quarter[2]},{cfx}]"


def _arcdata(p: WeldProcedure) -> str:
    return f"[0,0,{_n(p.voltage_v, 2)},{_n(p.wire_feed_m_min, 2)},0,{_n(p.current_a, 1)},0,0,0]"


def _procedure_data(k: int, p: WeldProcedure) -> list[str]:
    w = p.weave
    shape = _SHAPE[w.pattern] if w.active else 0
    length = p.travel_speed_mm_s / w.frequency_hz if w.active else 0.0
    zero = "[0,0,0,0,0,0,0,0,0]"
    return [
        f"  ! procedure {p.name}: {p.process}, {p.wire}, {p.gas}; leg {p.leg_mm:g} mm",
        f"  PERS seamdata sm{k} := [0,0.3,{_arcdata(p)},0,0,0,{_n(p.crater_start_s, 2)},0,{zero},0,"
        f"{_n(p.crater_end_s, 2)},0.05,0,{zero},0.5];",
        f"  PERS welddata wd{k} := [{_n(p.travel_speed_mm_s, 2)},0,{_arcdata(p)},{zero}];",
        f"  PERS weavedata wv{k} := [{shape},0,{_n(length, 2)},{_n(w.width_mm, 2)},0,{_n(w.dwell_s[0], 2)},0,"
        f"{_n(w.dwell_s[1], 2)},0,0,0,0,0,0,0];",
    ]


def rapid_text(job: ProgramJob) -> str:
    """The module text (module docstring)."""
    plan, robot, opt = job.plan, job.robot, job.options
    q0 = plan.segments[0].trajectory.q[0]
    X_FT = invert(robot.fk(q0, "tool0")) @ robot.fk(q0, "torch_tcp")
    X_BR = invert(job.X_RB)
    head = ["%%%", "  VERSION:1", "  LANGUAGE:ENGLISH", "%%%", "", f"MODULE {job.name}"]
    head += ["  ! Generated by the weld cell (cell.export.rapid) from a WeldPlan that passed the safety gate; mm, s."]
    head += header_lines(job.provenance, prefix="  ! ") if job.provenance is not None else []
    track = plan.track
    if track is not None:
        ax = ",".join(_n(v, 4) for v in track.axis_R)
        head += [
            f"  ! Linear track as eax_a (coordinated): axis [{ax}] in the robot base at eax_a = 0, limits"
            f" {_n(track.e1_min * 1000.0, 1)} .. {_n(track.e1_max * 1000.0, 1)} mm, speed {track.v_max * 1000:.0f}"
            " mm/s; every point's eax_a in mm, its pose in wobjPart measured from the base at eax_a = 0."
        ]
    cm = ",".join(_n(v, 1) for v in opt.load_cm_mm)
    decl = [
        f"  PERS tooldata tWeld := [TRUE,{pose_text(X_FT)},[{_n(opt.load_kg)},[{cm}],[1,0,0,0],0,0,0]];",
        f'  PERS wobjdata wobjPart := [FALSE,TRUE,"",{pose_text(job.X_RB)},[[0,0,0],[1,0,0,0]]];',
        f"  CONST jointtarget jHome := [[{','.join(_n(v) for v in np.degrees(plan.q_home))}],"
        f"{extax(0.0 if track else None)}];",
    ]
    procs: dict[tuple[str, int], int] = {}
    speeds: dict[int, str] = {}
    body = ["  PROC main()", "    ConfJ \\On;", "    ConfL \\On;", "    MoveAbsJ jHome, v1000, fine, tWeld;"]
    segs = plan.segments
    n, current = 0, ""

    def speed(seg: Segment) -> str:
        mm_s = max(1, round(seg.speed * 1000.0))
        if mm_s not in speeds:
            speeds[mm_s] = f"vL{mm_s}"
            decl.append(f"  CONST speeddata vL{mm_s} := [{mm_s},500,5000,1000];")
        return speeds[mm_s]

    def proc_index(seg: Segment) -> int:
        p = procedure_of(seg)
        key = (p.name, seg.pass_index)
        if key not in procs:
            procs[key] = len(procs) + 1
            decl.extend(_procedure_data(procs[key], p))
        return procs[key]

    for k, seg in enumerate(segs):
        nxt = segs[k + 1] if k + 1 < len(segs) else None
        if seg.seam_id and seg.seam_id != current:
            current = seg.seam_id
            body.append(f"    ! seam {current}")
        q = seg.trajectory.q[-1]
        if seg.kind == "move" and nxt is None and np.allclose(q, plan.q_home, atol=1e-9):
            body.append("    MoveAbsJ jHome, v1000, fine, tWeld;")
            continue
        n += 1
        on_track = seg.kind != "move" or track is not None  # X_end: the TCP in R with the base where E1 put it
        X = X_BR @ np.asarray(seg.X_end) if on_track else X_BR @ robot.fk(q, "torch_tcp")
        ext = extax(seg.e1_end if track else None)
        decl.append(f"  CONST robtarget p{n} := [{pose_text(X)[1:-1]},{confdata(robot, q)},{ext}];")
        wobj = "tWeld \\WObj:=wobjPart"
        arc_next = nxt is not None and nxt.kind == "weld"
        if seg.kind == "weld":
            i = proc_index(seg)
            instr = "ArcL" if arc_next else "ArcLEnd"
            body.append(f"    {instr} p{n}, {speed(seg)}, sm{i}, wd{i} \\Weave:=wv{i}, fine, {wobj};")
        elif arc_next and nxt is not None:
            i = proc_index(nxt)
            body.append(f"    ArcLStart p{n}, {speed(seg)}, sm{i}, wd{i} \\Weave:=wv{i}, fine, {wobj};")
        elif seg.kind == "move":
            body.append(f"    MoveJ p{n}, v1000, fine, {wobj};")
        else:
            body.append(f"    MoveL p{n}, {speed(seg)}, fine, {wobj};")
    body += ["  ENDPROC", "ENDMODULE", ""]
    return "\n".join([*head, *decl, "", *body])


class RapidPost:
    """The ABB RAPID post-processor (:class:`~cell.export.program.PostProcessor`): ``NAME.mod``."""

    name = "rapid"

    def texts(self, job: ProgramJob) -> dict[str, str]:
        return {f"{job.name}.mod": rapid_text(job)}
