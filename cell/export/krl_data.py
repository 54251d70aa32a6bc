"""The KRL texts of values: frames, E6POS / E6AXIS points, KUKA.ArcTech's weld data sets and the setup fold, in mm and
degrees (A, B, C about Z, Y, X); the data sets' parts and the power source's channels: docs/reference.md section 5."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from cell.config.export import KrlOptions
from cell.export.program import ProgramJob, procedure_of
from cell.geometry import FloatArray, invert, make_pose, matrix_to_rpy, rot_y
from cell.types.procedure import WeavePattern, WeldProcedure
from cell.types.track import LinearTrack

X_TOOL = make_pose(rot_y(-math.pi / 2.0))  # torch_tcp -> KRL tool frame (KUKA tool direction #X: x along the wire)
PREFLOW_S = 0.3  # gas pre-flow before ignition [s]
POSTFLOW_S = 0.5  # gas post-flow after the crater [s]
BURNBACK_S = 0.05  # wire burn-back after the arc [s]
_WEAVE: dict[WeavePattern, str] = {"none": "#None", "zigzag": "#Triangle", "triangle": "#Triangle", "circle": "#Spiral"}


def num(v: float, digits: int = 3) -> str:
    """A REAL as KRL reads it (no ``-0.000``)."""
    s = f"{v:.{digits}f}"
    return s[1:] if s.startswith("-") and float(s) == 0.0 else s


def frame_text(X: npt.ArrayLike) -> str:
    """``{X .., Y .., Z .., A .., B .., C ..}`` of a pose (4, 4) [m] in mm and degrees."""
    X = np.asarray(X, dtype=float)
    roll, pitch, yaw = np.degrees(matrix_to_rpy(X[:3, :3]))
    x, y, z = X[:3, 3] * 1000.0
    return f"{{X {num(x)}, Y {num(y)}, Z {num(z)}, A {num(yaw)}, B {num(pitch)}, C {num(roll)}}}"


def e6pos(X: FloatArray, s: int, t: int, e1: float = 0.0, ext: Mapping[int, float] | None = None) -> str:
    """An E6POS of a pose (4, 4) [m] with Status and Turn; E1 the linear track's position [m] (written in mm),
    ``ext`` other external axes by number [deg] (a positioner's E2, E3), the rest 0."""
    return frame_text(X)[:-1] + f", S {s}, T {t}, {_e_axes(e1, ext)}}}"


def e6axis(q: FloatArray, e1: float = 0.0, ext: Mapping[int, float] | None = None) -> str:
    """An E6AXIS of joint values (6,) [rad] in degrees; E1 the linear track's position [m] (written in mm), ``ext``
    other external axes by number [deg], the rest 0."""
    a = ", ".join(f"A{i + 1} {num(v)}" for i, v in enumerate(np.degrees(q)))
    return f"{{{a}, {_e_axes(e1, ext)}}}"


def _e_axes(e1: float, ext: Mapping[int, float] | None) -> str:
    values = [f"E1 {_e1(e1)}", *(f"E{i} 0.0" for i in range(2, 7))]
    for i, v in (ext or {}).items():
        values[i - 1] = f"E{i} {num(v)}"
    return ", ".join(values)


def _e1(e1: float) -> str:
    """E1 [m] as KRL writes it, in mm (0 as the unused axes are: ``0.0``)."""
    return num(e1 * 1000.0) if e1 != 0.0 else "0.0"


def _channels(p: WeldProcedure) -> str:
    ch = [p.wire_feed_m_min, p.voltage_v, p.current_a, 0.0, 0.0, 0.0, 0.0, 0.0]
    return ",".join(f"Channel{i + 1} {num(v)}" for i, v in enumerate(ch))


def _ids(job_mode: str, param_set: str) -> str:
    return f'JobModeId[] "{job_mode}",ParamSetId[] "{param_set}"'


def weave_text(p: WeldProcedure) -> str:
    """ArcTech's ``Weave``: pattern, wavelength along the seam [mm], amplitude (half the width) [mm], dwells [s]."""
    w = p.weave
    if not w.active:
        return "Weave {Pattern #None,Length 4.0,Amplitude 0.0,Angle 0.0,LeftSideDelay 0.0,RightSideDelay 0.0}"
    length = p.travel_speed_mm_s / w.frequency_hz
    return (
        f"Weave {{Pattern {_WEAVE[w.pattern]},Length {num(length)},Amplitude {num(w.width_mm / 2.0)},Angle 0.0,"
        f"LeftSideDelay {num(w.dwell_s[0])},RightSideDelay {num(w.dwell_s[1])}}}"
    )


def weld_text(p: WeldProcedure, job_mode: str, param_set: str) -> str:
    """ArcTech's ``Weld``: the path velocity [m/s] and the channels."""
    v = p.travel_speed_mm_s / 1000.0
    return f"Weld {{{_ids(job_mode, param_set)},Velocity {num(v, 5)},{_channels(p)}}}"


def arc_data(name: str, kind: str, p: WeldProcedure, job_mode: str, param_set: str) -> str:
    """``DECL stArcDat_T name={...}`` of an ARC_ON (``on``), ARC_SWI (``swi``) or ARC_OFF (``off``) statement."""
    head = f'DECL stArcDat_T {name}={{WdatId[] "{name}",'
    if kind == "on":
        strike = (
            f"Strike {{{_ids(job_mode, param_set)},StartTime {num(p.crater_start_s)},PreFlowTime {num(PREFLOW_S)},"
            f"{_channels(p)},PurgeTime 0.0}}"
        )
        return head + f"{strike},{weld_text(p, job_mode, param_set)},{weave_text(p)}}}"
    if kind == "swi":
        return head + f"{weld_text(p, job_mode, param_set)},{weave_text(p)}}}"
    if kind == "off":
        crater = (
            f"Crater {{{_ids(job_mode, param_set)},CraterTime {num(p.crater_end_s)},PostflowTime {num(POSTFLOW_S)},"
            f"{_channels(p)},BurnBackTime {num(BURNBACK_S)}}}"
        )
        return head + crater + "}"
    raise ValueError(f"arc statement kind {kind!r} is not on, swi or off")


def procedure_line(p: WeldProcedure, pass_index: int) -> str:
    """One comment line naming a procedure's figures (the setup block and each weld block)."""
    w = p.weave
    weave = f"{w.pattern} {w.width_mm:g} mm at {w.frequency_hz:g} Hz" if w.active else "none"
    return (
        f"procedure {p.name} pass {pass_index + 1}/{len(p.passes)}: {p.process}, {p.wire}; {p.current_a:g} A,"
        f" {p.voltage_v:g} V, wire {p.wire_feed_m_min:g} m/min, {p.travel_speed_mm_s:g} mm/s, leg {p.leg_mm:g} mm,"
        f" weave {weave}, craters {p.crater_start_s:g}/{p.crater_end_s:g} s"
    )


def setup_block(job: ProgramJob) -> list[str]:
    """The setup fold: TOOL_DATA / LOAD_DATA / BASE_DATA [n] and XHOME to enter, each weld's procedure."""
    opt = job.options
    q_any = job.plan.segments[0].trajectory.q[0]
    X_FT = invert(job.robot.fk(q_any, "tool0")) @ job.robot.fk(q_any, "torch_tcp") @ X_TOOL
    cm = frame_text(make_pose(p=np.asarray(opt.load_cm_mm) / 1000.0))
    lines = [
        ";FOLD SETUP: the values to enter before the first run",
        f";- TOOL_DATA[{opt.tool_index}] = {frame_text(X_FT)} ; torch TCP in $FLANGE, tool direction #X = the wire",
        f";- LOAD_DATA[{opt.tool_index}] = {{M {opt.load_kg:.3f}, CM {cm}, J {{X 0.0, Y 0.0, Z 0.0}}}}",
        f";- BASE_DATA[{opt.base_index}] = {frame_text(job.X_RB)} ; the part (aligned map) in $WORLD = $ROBROOT"
        if job.external is None
        else f";- BASE_DATA[{opt.base_index}] = {frame_text(job.external.X_FB)} ; the part's base on the positioner's"
        f" faceplate (MACHINE_DEF[{job.external.machine}]'s flange)",
        f";- XHOME = {e6axis(job.plan.q_home)} ; in $config.dat; the program sets $H_POS = XHOME",
    ]
    if job.X_WR is not None:
        lines.append(f";- robot mounting in the cell (X_WR, information only) = {frame_text(job.X_WR)}")
    if opt.arc == "signals":
        lines.append(
            f";- arc: $OUT[{opt.arc_on_output}] on/off, $IN[{opt.arc_ok_input}] arc established (timeout"
            f" {opt.arc_timeout_s:g} s)"
        )
    seen: set[tuple[str, int]] = set()
    for seg in job.plan.segments:
        if seg.kind == "weld":
            p = procedure_of(seg)
            if (p.name, seg.pass_index) not in seen:
                seen.add((p.name, seg.pass_index))
                lines.append(f";- {procedure_line(p, seg.pass_index)}")
    return [*lines, ";ENDFOLD"]


def track_header(track: LinearTrack) -> list[str]:
    """The header comment of a plan on a linear track: the axis E1, its limits and how the frames chain."""
    ax = ", ".join(f"{v:.4f}" for v in track.axis_R)
    return [
        f";- Linear track E1 (KL-style, mathematically coupled): axis [{ax}] in $ROBROOT at E1 = 0; software limits"
        f" {track.e1_min * 1000:.1f} .. {track.e1_max * 1000:.1f} mm; speed {track.v_max * 1000:.0f} mm/s,"
        f" acceleration {track.a_max * 1000:.0f} mm/s^2.",
        ";- Every point carries its E1 [mm]; its X, Y, Z stay in BASE_DATA measured from the base at E1 = 0"
        " ($ERSYSROOT = $ROBROOT at E1 = 0): the robot base at E1 is there moved by E1 along the axis.",
    ]


def main_ini(opt: KrlOptions, far: str, programs: str) -> list[str]:
    """The INI fold, tool, PTP speed and the home check of a KRL main program that calls one program per side or
    pose (``programs``: what they are, for the comment); ``far``: the KRL condition that XHOME is not the planned
    home XHOME_PLAN (the program halts then)."""
    return [
        ";FOLD INI", ";FOLD BASISTECH INI", "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
        "INTERRUPT ON 3", "BAS(#INITMOV, 0)", ";ENDFOLD (BASISTECH INI)", ";FOLD USER INI", ";ENDFOLD (USER INI)",
        ";ENDFOLD (INI)", "",
        f"BAS(#TOOL, {opt.tool_index}) ; the torch's TOOL_DATA and LOAD_DATA (the {programs}' setup blocks)",
        f"BAS(#VEL_PTP, {opt.ptp_percent})", f"BAS(#ACC_PTP, {opt.ptp_percent})",
        f"IF {far} THEN",
        "  HALT ; $config.dat's XHOME is not the planned home XHOME_PLAN: correct it first",
        "ENDIF",
        "$H_POS = XHOME",
        "PTP XHOME ; first motion: fully defined axis point (block coincidence)",
    ]  # fmt: skip
