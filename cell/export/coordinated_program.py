"""The programs of a curved seam welded with the positioner turning the part (docs/positioner.md, "Coordinated
motion"): every point in the base on the faceplate with its own positioner axes. KRL: ``$BASE = EK(...)`` on the
positioner's chain, CIRC moves where the seam is a circle in the part (else LIN chords) whose E6POS carry E2 (tilt)
and E3 (rotate) changing from point to point: the controller interpolates each move in the turning base, the axes
moved synchronously from its start to its end; RAPID: the work object on the mechanical unit (``ufmec``), every
robtarget's eax_b / eax_c moving, ``ArcC`` circles or ``ArcL`` chords."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cell.config.export import KrlOptions
from cell.coordinated.record import CoordinatedWeld
from cell.export.checks.positioner import chain_line
from cell.export.circles import CIRCLE_TOL_M, MAX_SWEEP_RAD, circle_through, fit_circle, swept
from cell.export.krl_data import X_TOOL, e6axis, e6pos, frame_text, num, procedure_line
from cell.export.program import write_texts
from cell.export.rapid import _procedure_data as procedure_data
from cell.export.rapid import confdata, pose_text
from cell.export.status_turn import ArmGeometry, status_turn
from cell.geometry import FloatArray, invert
from cell.types.positioner import TiltRotatePositioner
from cell.types.procedure import WeldProcedure
from cell.types.robot import Kinematics

CHORD_TOL_M = 0.0001  # [m] a chord stays this close to every knot it stands for (in the part's frame)
MAX_TURN_DEG = 10.0  # and the rotate axis turns at most this much along it
MAX_AXES_DEV_RAD = math.radians(0.5)  # the planned axes this close to the controller's interpolation along a move
MIN_CIRC_SWEEP_RAD = math.radians(10.0)  # a circle is split into moves down to this angle before chords are taken


@dataclass(frozen=True)
class CoordMove:
    """One move of a coordinated weld from knot ``start`` to knot ``end``: ``CIRC`` through knot ``aux``, turning
    ``angle`` [rad] about the circle planned (``centre`` (3,) in F, ``radius`` [m]); or ``LIN`` within
    ``chord`` [m] of the knots it passes (in F). ``axes_dev`` [rad]: the planned axes' largest departure from the
    controller's synchronous interpolation (the axes moved in proportion to the path from start to end)."""

    kind: str
    start: int
    end: int
    aux: int = -1
    angle: float = 0.0
    centre: FloatArray | None = None
    radius: float = 0.0
    chord: float = 0.0
    axes_dev: float = 0.0


def _axes_dev(cw: CoordinatedWeld, a: int, b: int) -> float:
    s, A = np.asarray(cw.s)[a : b + 1], np.asarray(cw.knot_axes)[a : b + 1]
    f = (s - s[0]) / max(float(s[-1] - s[0]), 1e-12)
    return float(np.abs(A - (A[0] + f[:, None] * (A[-1] - A[0]))).max())


def coordinated_moves(cw: CoordinatedWeld, woven: bool = True) -> list[CoordMove]:
    """The weld's moves: circular ones when its knots in the part's frame lie on a circle (within
    :data:`CIRCLE_TOL_M`), each at most :data:`MAX_SWEEP_RAD` and split further (into four times as many, or moves
    of :data:`MIN_CIRC_SWEEP_RAD`, whichever are more) until the planned axes stay within :data:`MAX_AXES_DEV_RAD`
    of the controller's interpolation; else the chords of :func:`chord_knots`. ``woven`` False: along the pass's
    line (the weave left to the controller)."""
    p = _knots(cw, woven)
    centre, normal, r, err = fit_circle(p)
    if err <= CIRCLE_TOL_M and r > 0.0:
        ang = np.abs(swept(p, centre, normal))
        k0 = max(1, math.ceil(ang[-1] / MAX_SWEEP_RAD - 1e-9))
        for k in range(k0, max(4 * k0, math.floor(ang[-1] / MIN_CIRC_SWEEP_RAD + 1e-9)) + 1):
            cuts = [int(np.argmin(np.abs(ang - ang[-1] * i / k))) for i in range(k + 1)]
            cuts[0], cuts[-1] = 0, len(p) - 1
            moves = []
            for a, b in itertools.pairwise(cuts):
                m = int(np.argmin(np.abs(ang - 0.5 * (ang[a] + ang[b]))))
                sweep = float(ang[b] - ang[a])
                moves.append(CoordMove("CIRC", a, b, m, sweep, centre, r, axes_dev=_axes_dev(cw, a, b)))
            if all(mv.axes_dev <= MAX_AXES_DEV_RAD and mv.start < mv.aux < mv.end for mv in moves):
                return moves
    knots = chord_knots(cw, woven=woven)
    return [CoordMove("LIN", a, b, chord=_chord(p, a, b), axes_dev=_axes_dev(cw, a, b))
            for a, b in itertools.pairwise(knots)]  # fmt: skip


def _knots(cw: CoordinatedWeld, woven: bool) -> FloatArray:
    """(m, 3) [m] the weld's knots in F: the torch's (woven) or its pass line's."""
    return np.asarray(cw.X_FT if woven else cw.line_FT)[:, :3, 3]


def program_path_off(cw: CoordinatedWeld, moves: list[CoordMove], woven: bool = True) -> float:
    """[m] the largest distance of a weld knot (in the part's frame) from the move that stands for it as the
    controller runs it: the circle through a CIRC's start, auxiliary and end points, or a LIN's chord."""
    p = _knots(cw, woven)
    worst = 0.0
    for mv in moves:
        three = circle_through(p[mv.start], p[mv.aux], p[mv.end]) if mv.kind == "CIRC" else None
        if three is None:
            worst = max(worst, _chord(p, mv.start, mv.end))
            continue
        centre, r, _ = three
        normal = np.cross(p[mv.aux] - p[mv.start], p[mv.end] - p[mv.start])
        normal /= np.linalg.norm(normal)
        d = p[mv.start : mv.end + 1] - centre
        h = d @ normal
        worst = max(worst, float(np.hypot(np.linalg.norm(d - np.outer(h, normal), axis=1) - r, h).max()))
    return worst


def _chord(p: FloatArray, a: int, b: int) -> float:
    """The largest distance [m] of the knots p[a..b] from the chord p[a]-p[b]."""
    u = (p[b] - p[a]) / max(float(np.linalg.norm(p[b] - p[a])), 1e-12)
    mid = p[a : b + 1] - p[a]
    return float(np.linalg.norm(mid - np.outer(mid @ u, u), axis=1).max())


def chord_knots(cw: CoordinatedWeld, tol: float = CHORD_TOL_M, woven: bool = True) -> list[int]:
    """The knots written (indices, first and last included): each chord the longest whose knots between lie
    within ``tol`` [m] of it in the part's frame and along which each axis (tilt, rotate) turns at most
    ``MAX_TURN_DEG``."""
    p = _knots(cw, woven)
    A = np.degrees(np.asarray(cw.knot_axes))
    out, i, n = [0], 0, len(p)
    while i < n - 1:
        j = i + 1
        while j + 1 < n and float(np.abs(A[j + 1] - A[i]).max()) <= MAX_TURN_DEG:
            a, b = p[i], p[j + 1]
            u = (b - a) / max(float(np.linalg.norm(b - a)), 1e-12)
            mid = p[i + 1 : j + 1] - a
            if float(np.linalg.norm(mid - np.outer(mid @ u, u), axis=1).max()) > tol:
                break
            j += 1
        out.append(j)
        i = j
    return out


def _moves_line(moves: list[CoordMove]) -> str:
    """The comment that says how the weld is written and how near the controller's axes keep to the plan."""
    kinds = ", ".join(f"{sum(mv.kind == k for mv in moves)} {k}" for k in ("CIRC", "LIN") if any(mv.kind == k
                      for mv in moves))  # fmt: skip
    dev = max(math.degrees(mv.axes_dev) for mv in moves)
    return (f";- The weld: {kinds} in the turning base (the seam's path in the part); E2/E3 within {dev:.3f} deg of"
            " the plan where the controller moves them in proportion to the path along each move")  # fmt: skip


def _tilt_text(cw: CoordinatedWeld) -> str:
    """The weld's tilt [deg]: one value where it is held, else the range it follows."""
    t = np.degrees(np.asarray(cw.knot_axes)[:, 0])
    return f"{t[0]:.1f} deg" if np.ptp(t) < 0.05 else f"{t.min():.1f} .. {t.max():.1f} deg (following the seam)"


def _header(pos: TiltRotatePositioner, cw: CoordinatedWeld, X_RB: FloatArray) -> list[str]:
    lim = [(n, name, math.degrees(a.q_min), math.degrees(a.q_max)) for n, name, a in
           ((2, "tilt", pos.tilt), (3, "rotate", pos.rotate))]  # fmt: skip
    axes = "; ".join(f"E{n} {name} limits {lo:.1f} .. {hi:.1f} deg" for n, name, lo, hi in lim)
    lo_hi = cw.span_m
    span = "" if lo_hi is None else f"; an open arc of it, {lo_hi[0] * 1000:.1f} to {lo_hi[1] * 1000:.1f} mm along it"
    return [
        f";- Positioner (tilt-rotate, coordinated, MACHINE_DEF[2]): {axes}.",
        ";- Coordinated motion: the points are in BASE_DATA on the positioner's faceplate ($BASE = EK(...)) and each"
        " carries its own E2 and E3: the rotate axis turns the part under a nearly still torch, the controller moving"
        " the arm and the axes together along each move (CIRC or LIN) in the turning base.",
        f";- The base at this program's axes in $ROBROOT = {frame_text(X_RB)} (at its first weld point's E2 and E3:"
        " what EK gives; for checking)",
        chain_line(pos.X_RP, pos.tilt_height_m, pos.faceplate_offset_m, np.eye(4)),
        f";- Seam {cw.seam_id}: tilt {_tilt_text(cw)} (the fillet in PA), rotate"
        f" {math.degrees(cw.knot_axes[0, 1]):.1f} .. {math.degrees(cw.knot_axes[-1, 1]):.1f} deg, travel"
        f" {cw.speed * 1000:.1f} mm/s along the part, overlap {cw.overlap * 1000:.1f} mm{span}",
    ]


def coordinated_krl(
    cw: CoordinatedWeld,
    robot: Kinematics,
    pos: TiltRotatePositioner,
    name: str,
    procedure: WeldProcedure | None = None,
    opt: KrlOptions | None = None,
) -> tuple[str, str]:
    """(src, dat) of the program ``name`` (upper-case): home, the synchronised PTP to the approach (arm and
    positioner), the approach, the arc on, the chords with E2/E3 moving, the crater, the arc off, the depart and
    home (the positioner back at its home)."""
    o = opt or KrlOptions()
    procedure = procedure or cw.procedure
    geo = ArmGeometry.of(robot)
    X_RB0 = pos.X_R_F(*cw.knot_axes[0])
    q_home = cw.q[-1]
    ext = lambda a: {2: math.degrees(a[0]), 3: math.degrees(a[1])}  # noqa: E731
    q_app = cw.q[np.searchsorted(cw.times, cw.pieces[1][1])]
    q_dep = cw.q[np.searchsorted(cw.times, cw.pieces[3][2]) - 1]
    X_FT = np.asarray(cw.X_FT)
    X_q = invert(robot.fk(q_app, "tool0")) @ robot.fk(q_app, "torch_tcp") @ X_TOOL
    dat = [f"DEFDAT {name} PUBLIC", f"DECL E6AXIS XAPP={e6axis(q_app, 0.0, ext(cw.knot_axes[0]))}"]
    src = ["&ACCESS RVP", "&REL 1", f"DEF {name}( )",
           ";- Generated by the weld cell (cell.export.coordinated_program): a curved seam welded with the positioner"
           " turning the part; mm, deg, s.", *_header(pos, cw, X_RB0), ";FOLD SETUP: the values to enter before the"
           " first run", f";- TOOL_DATA[{o.tool_index}] = {frame_text(X_q)} ; torch TCP in $FLANGE, #X = the wire",
           f";- BASE_DATA[{o.base_index}] = {frame_text(np.eye(4))} ; the part's base on the positioner's faceplate"
           " (MACHINE_DEF[2]'s flange)", f";- XHOME = {e6axis(q_home)} ; in $config.dat"]  # fmt: skip
    src += [f";- {procedure_line(procedure, 0)}"] if procedure is not None else []
    src += [";ENDFOLD", ";FOLD INI", "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )", "INTERRUPT ON 3",
            "BAS(#INITMOV, 0)", ";ENDFOLD (INI)", f"BAS(#TOOL, {o.tool_index})",
            f"$BASE = EK(MACHINE_DEF[2].ROOT, MACHINE_DEF[2].MECH_TYPE, BASE_DATA[{o.base_index}]) ; the part on the"
            " faceplate", f"BAS(#VEL_PTP, {o.ptp_percent})", "$H_POS = XHOME", "PTP XHOME",
            "PTP XAPP ; the arm and the positioner together: the fillet in PA at the torch"]  # fmt: skip

    def point(k: int, X: FloatArray, q: FloatArray, a: FloatArray) -> str:
        s, t = status_turn(robot, q, geo)
        dat.append(f"DECL E6POS XP{k}={e6pos(X @ X_TOOL, s, t, 0.0, ext(a))}")
        return f"XP{k}"

    n = 1
    X_start = X_FT[0].copy()
    app = float(np.linalg.norm(robot.fk(q_app)[:3, 3] - robot.fk(cw.knot_q[0])[:3, 3]))
    X_start[:3, 3] -= app * X_start[:3, 2]
    src += [f"$VEL.CP = {0.05:.4f} ; [m/s] approach", f"LIN {point(n, X_start, q_app, cw.knot_axes[0])}"]
    n += 1
    src.append(f"LIN {point(n, X_FT[0], cw.knot_q[0], cw.knot_axes[0])} ; the weld's start")
    ms = round(o.arc_timeout_s * 1000.0)
    src += [f"$OUT[{o.arc_on_output}] = TRUE ; arc on, seam {cw.seam_id}", "$TIMER_STOP[1] = TRUE",
            f"$TIMER[1] = -{ms}", "$TIMER_STOP[1] = FALSE", f"WAIT FOR $IN[{o.arc_ok_input}] OR $TIMER_FLAG[1]",
            "$TIMER_STOP[1] = TRUE", f"IF NOT $IN[{o.arc_ok_input}] THEN", f"  $OUT[{o.arc_on_output}] = FALSE",
            f"  HALT ; no arc within {o.arc_timeout_s:g} s: arc off, stopped", "ENDIF",
            f"$VEL.CP = {cw.speed:.4f} ; [m/s] {cw.speed * 1000:.1f} mm/s along the turning part"]  # fmt: skip
    moves = coordinated_moves(cw)
    src += [_moves_line(moves)]
    src += [";- The weave is in the points (the path weaves in the part's frame): no weave package"] * (
        cw.weave_F is not None
    )
    if any(mv.kind == "CIRC" for mv in moves):
        src.append("$CIRC_TYPE = #BASE ; the torch's orientation interpolated in the turning base (the part's)")
    for mv in moves:
        if mv.kind == "CIRC" and mv.centre is not None:
            n += 1
            aux = point(n, X_FT[mv.aux], cw.knot_q[mv.aux], cw.knot_axes[mv.aux])
            c = ", ".join(f"{v:.3f}" for v in mv.centre * 1000.0)
            src.append(f";- circle r = {mv.radius * 1000.0:.3f} mm, centre [{c}] mm (base), angle"
                       f" {math.degrees(abs(mv.angle)):.3f} deg")  # fmt: skip
            n += 1
            end = point(n, X_FT[mv.end], cw.knot_q[mv.end], cw.knot_axes[mv.end])
            three = circle_through(*(X_FT[i][:3, 3] for i in (mv.start, mv.aux, mv.end)))
            src.append(f"CIRC {aux}, {end}, CA {math.degrees(three[2] if three else abs(mv.angle)):.3f}")
            continue
        n += 1
        src.append(f";- chord within {mv.chord * 1000.0:.3f} mm of the planned path (<= {CHORD_TOL_M * 1000:g} mm)")
        src.append(f"LIN {point(n, X_FT[mv.end], cw.knot_q[mv.end], cw.knot_axes[mv.end])}")
    crater = procedure.crater_end_s if procedure is not None else 0.3
    src += [f"WAIT SEC {num(crater)} ; crater fill at rest", f"$OUT[{o.arc_on_output}] = FALSE ; arc off"]
    X_end = X_FT[-1].copy()
    X_end[:3, 3] -= float(np.linalg.norm(robot.fk(q_dep)[:3, 3] - robot.fk(cw.knot_q[-1])[:3, 3])) * X_end[:3, 2]
    n += 1
    src += [f"$VEL.CP = {0.05:.4f} ; [m/s] depart", f"LIN {point(n, X_end, q_dep, cw.knot_axes[-1])}"]
    src += ["PTP XHOME ; back home, the positioner to its home", "END", ""]
    return "\n".join(src), "\n".join([*dat, "ENDDAT", ""])


def coordinated_rapid(
    cw: CoordinatedWeld, robot: Kinematics, name: str, procedure: WeldProcedure | None = None, unit: str = "STN1"
) -> str:
    """The RAPID module ``name``: ``ActUnit``, the work object moved by the unit (``ufmec``), ``ArcLStart`` then
    ``ArcC`` circles or ``ArcL`` chords along the pass's line whose robtargets' eax_b (tilt) and eax_c (rotate)
    change, the weave (if any) the controller's (``\\Weave``, the weld procedure's ``weavedata``), ``DeactUnit``."""
    procedure = procedure or cw.procedure
    deg = lambda a: f"[9E9,{math.degrees(a[0]):.3f},{math.degrees(a[1]):.3f},9E9,9E9,9E9]"  # noqa: E731
    q0 = cw.knot_q[0]
    X_q = invert(robot.fk(q0, "tool0")) @ robot.fk(q0, "torch_tcp")
    v = max(1, round(cw.speed * 1000.0))
    decl = [f"  PERS tooldata tWeld := [TRUE,{pose_text(X_q)},[3,[0,0,100],[1,0,0,0],0,0,0]];",
            f'  PERS wobjdata wobjPart := [FALSE,FALSE,"{unit}",[[0,0,0],[1,0,0,0]],[[0,0,0],[1,0,0,0]]];',
            f"  CONST jointtarget jHome := [[{','.join(f'{d:.3f}' for d in np.degrees(cw.q[-1]))}],"
            "[9E9,0,0,9E9,9E9,9E9]];",
            f"  CONST speeddata vWeld := [{v},500,5000,1000];"]  # fmt: skip
    body = ["  PROC main()", "    ConfL \\Off;", f"    ActUnit {unit};", "    MoveAbsJ jHome, v1000, fine, tWeld;"]
    moves, names, line = coordinated_moves(cw, woven=False), list[str](), cw.line_FT
    weave = " \\Weave:=wv1" if procedure is not None else ""

    def target(i: int) -> str:
        names.append(f"p{len(names) + 1}")
        decl.append(f"  CONST robtarget {names[-1]} := [{pose_text(line[i])[1:-1]},"
                    f"{confdata(robot, cw.knot_q[i])},{deg(cw.knot_axes[i])}];")  # fmt: skip
        return names[-1]

    body.append(f"    ArcLStart {target(0)}, v100, sm1, wd1{weave}, fine, tWeld \\WObj:=wobjPart;")
    for k, mv in enumerate(moves):
        end = "End" if k == len(moves) - 1 else ""
        to = [target(mv.aux), target(mv.end)] if mv.kind == "CIRC" else [target(mv.end)]
        instr = ("ArcC" if mv.kind == "CIRC" else "ArcL") + end
        body.append(f"    {instr} {', '.join(to)}, vWeld, sm1, wd1{weave}, fine, tWeld \\WObj:=wobjPart;")
    sp = cw.speed * 1000.0
    default = ["  PERS seamdata sm1 := [0,0.3,[0,0,21.5,7,0,190,0,0,0],0,0,0,0,0,[0,0,0,0,0,0,0,0,0],0,0.3,0.05,0,"
               "[0,0,0,0,0,0,0,0,0],0.5];", f"  PERS welddata wd1 := [{sp:.2f},0,[0,0,21.5,7,0,190,0,0,0],"
               "[0,0,0,0,0,0,0,0,0]];"]  # fmt: skip
    decl += procedure_data(1, procedure) if procedure is not None else default
    body += ["    MoveAbsJ jHome, v1000, fine, tWeld;", f"    DeactUnit {unit};", "  ENDPROC", "ENDMODULE", ""]
    head = ["%%%", "  VERSION:1", "  LANGUAGE:ENGLISH", "%%%", "", f"MODULE {name}",
            f"  ! Generated by the weld cell (cell.export.coordinated_program): {cw.seam_id} welded with {unit}"
            " turning the part (coordinated: wobjPart moved by the unit, every robtarget's eax_b tilt and eax_c"
            " rotate [deg] changing)."]  # fmt: skip
    return "\n".join([*head, *decl, "", *body])


def coordinated_names(stem: str, n: int) -> list[str]:
    """The programs' names of ``n`` coordinated welds, in the order they are played: ``stem``_c1, ... (24 at most)."""
    return [f"{stem}_c{k + 1}"[:24] for k in range(n)]


def write_coordinated_programs(
    controller: str,
    cws: list[CoordinatedWeld],
    robot: Kinematics,
    pos: TiltRotatePositioner,
    stem: str,
    out_dir: str | Path,
) -> list[Path]:
    """One program per coordinated weld (``stem``_c1, ...: :func:`coordinated_names`) into ``out_dir``; their
    paths."""
    texts: dict[str, str] = {}
    for name, cw in zip(coordinated_names(stem, len(cws)), cws, strict=True):
        if controller == "rapid":
            texts[f"{name}.mod"] = coordinated_rapid(cw, robot, name)
        else:
            src, dat = coordinated_krl(cw, robot, pos, name.upper())
            texts[f"{name.upper()}.src"], texts[f"{name.upper()}.dat"] = src, dat
    return write_texts(texts, out_dir)
