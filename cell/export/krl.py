"""KUKA KRL export of a welding plan: ``NAME.src`` and ``NAME.dat``, every point an exact stop but those the plan
blends (``C_DIS``, the plan's zone), the arc by KUKA.ArcTech inline forms or plain signals. What the program holds,
in order: docs/programs.md; the KRL facts it relies on: docs/reference.md section 5."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.config.export import KrlOptions
from cell.export.circles import CHORD_TOL_M, Move, base_at, curve_moves
from cell.export.krl_data import X_TOOL, arc_data, e6axis, e6pos, num, procedure_line, setup_block, track_header
from cell.export.krl_external import base_lines, positioner_header, positioner_move
from cell.export.program import ProgramJob, not_welded_lines, procedure_of, write_texts
from cell.export.status_turn import ArmGeometry, status_turn
from cell.geometry import FloatArray, invert
from cell.provenance import header_lines
from cell.types.plan import Segment, WeldPlan
from cell.types.robot import Kinematics

HOME_TOL_DEG = 0.5  # the guard's tolerance between $config.dat's XHOME and the planned home
HOME_TOL_MM = 0.5  # the same for the linear track's E1 [mm]
_ARC = {
    "on": ("ARCON", "arconlin", "ArcOn"),
    "swi": ("ARCSWI", "arcswilin", "ArcSwi"),
    "off": ("ARCOFF", "arcofflin", "ArcOff"),
}


class _Program:
    """The two files' lines as they are built."""

    def __init__(self, job: ProgramJob) -> None:
        self.job, self.opt = job, job.options
        self.src: list[str] = []
        self.dat: list[str] = [f"DEFDAT {job.name} PUBLIC"]
        self.n = 0  # points
        self.w = 0  # weld data sets
        self.geo = ArmGeometry.of(job.robot)
        self.X_BR = invert(job.X_RB)
        self.last_vel = -1.0
        self.last_apo = -1.0
        self.ext = job.external.by_number() if job.external is not None else None  # a positioner's E2, E3 [deg]

    def approx(self, seg: Segment) -> str:
        """The motion's approximation: `` C_DIS`` (after setting ``$APO.CDIS`` to its zone in mm) when the plan
        blends it into the next motion, else "" (an exact stop)."""
        if seg.zone_m <= 0.0:
            return ""
        mm = round(seg.zone_m * 1000.0, 1)
        if abs(mm - self.last_apo) > 1e-9:
            self.src.append(f"$APO.CDIS = {mm:.1f} ; [mm] blended into the next motion this far from its end")
            self.last_apo = mm
        return " C_DIS"

    def point(self, seg: Segment) -> str:
        """Declare the segment's end as the next point (E6POS in the base for a LIN, E6AXIS for a PTP); its name."""
        if seg.kind != "move":
            return self.pose_point(np.asarray(seg.X_end), seg.q_end, seg.e1_end)
        self.n += 1
        self.dat.append(f"DECL E6AXIS XP{self.n}={e6axis(seg.q_end, seg.e1_end, self.ext)}")
        return f"XP{self.n}"

    def pose_point(self, X_RT: FloatArray, q: FloatArray, e1: float) -> str:
        """Declare the TCP pose X_RT (4, 4) in R as the next point, an E6POS in the base with the status and turn of
        q (dof,) [rad]; its name."""
        self.n += 1
        s, t = status_turn(self.job.robot, q, self.geo)
        self.dat.append(f"DECL E6POS XP{self.n}={e6pos(self.X_BR @ X_RT @ X_TOOL, s, t, e1, self.ext)}")
        return f"XP{self.n}"

    def curve_motion(self, mv: Move, e1: float) -> tuple[str, str]:
        """(the motion, its end point's name) of one move of a curved weld, after the whole-line comment that
        states a circular move's planned circle (``cell krl check`` holds its points to it)."""
        if mv.kind == "CIRC" and mv.X_aux is not None and mv.centre is not None:
            aux = self.pose_point(mv.X_aux, mv.q_end, e1)
            end = self.pose_point(mv.X_end, mv.q_end, e1)
            c = (self.X_BR @ np.append(mv.centre, 1.0))[:3] * 1000.0
            self.src.append(
                f";- circle r = {mv.radius * 1000.0:.3f} mm, centre [{', '.join(f'{v:.3f}' for v in c)}] mm"
                f" (base), angle {np.degrees(mv.angle):.3f} deg"
            )
            return f"CIRC {aux}, {end}, CA {np.degrees(mv.angle):.3f}", end
        end = self.pose_point(mv.X_end, mv.q_end, e1)
        self.src.append(
            f";- chord within {mv.chord * 1000.0:.3f} mm of the planned path (<= {CHORD_TOL_M * 1000:g} mm)"
        )
        return f"LIN {end}", end

    def plain_lin(self, seg: Segment, note: str) -> None:
        if abs(seg.speed - self.last_vel) > 1e-9:
            self.src.append(f"$VEL.CP = {seg.speed:.4f} ; [m/s] {seg.speed * 1000:.1f} mm/s")
            self.last_vel = seg.speed
        c_dis = self.approx(seg)
        self.src.append(f"LIN {self.point(seg)}{c_dis} ; {note}")

    def arc_fold(self, kind: str, seg: Segment, data_of: Segment, move: tuple[str, str] | None = None) -> None:
        """One ArcTech inline form: ``kind`` on | swi | off, the motion to the end of ``seg`` (or ``move``: a curved
        weld's motion and its end point, :meth:`curve_motion`), the weld data of ``data_of``'s procedure."""
        fold, provider, step = _ARC[kind]
        p = procedure_of(data_of)
        self.w += 1
        wdat = f"WDAT{self.w}"
        self.dat.append(arc_data(wdat, kind, p, self.opt.job_mode, self.opt.param_set))
        xp = self.point(seg) if move is None else move[1]
        pname = xp[1:]
        motion = "PTP" if seg.kind == "move" else "LIN" if move is None else move[0].split()[0]
        provider = provider.replace("lin", "circ") if motion == "CIRC" else provider
        ti, bi = self.opt.tool_index, self.opt.base_index
        vel = f"{seg.speed:.4f}" if kind == "on" else "gArcBasVelDefinition"
        shown = f" Vel={num(seg.speed, 4)} m/s" if kind == "on" else ""
        which = f"{data_of.pass_index + 1}/{len(p.passes)}"  # the form's header, as ArcTech shows it
        self.dat += [
            f'DECL FDAT F{pname}={{TOOL_NO {ti},BASE_NO {bi},IPO_FRAME #BASE,POINT2[] " "}}',
            f"DECL LDAT LCPDAT{self.n}={{VEL {num(max(seg.speed, 1e-4), 4)},ACC 100.0,APO_DIST 100.0,APO_FAC 50.0,"
            "AXIS_VEL 100.0,AXIS_ACC 100.0,ORI_TYP #VAR,CIRC_TYP #BASE,JERK_FAC 50.0,GEAR_JERK 100.0,EXAX_IGN 0}",
            f'DECL stArcDat_T W{pname}={{WdatId[] "W{pname}"}}',
        ]
        args = f"{wdat}, W{pname}"
        self.src += [
            f";- {fold[:3]}_{fold[3:]} seam {seg.seam_id} procedure {p.name} pass {which}",
            f";FOLD {fold} {wdat} {motion} {pname}{shown} CPDAT{self.n} Tool[{ti}] Base[{bi}] ;%{{PE}}",
            ";FOLD Parameters ;%{h}",
            f";Params IlfProvider=kukaroboter.arctech.{provider}; Kuka.IsGlobalPoint=False; Kuka.PointName={pname};"
            f" Kuka.BlendingEnabled=False; Kuka.MoveDataName=CPDAT{self.n}; Kuka.VelocityPath={num(seg.speed, 4)};"
            f" Kuka.CurrentCDSetIndex=0; Kuka.MovementParameterFieldEnabled=True; ArcTech.WdatVarName={wdat}",
            ";ENDFOLD",
            "$BWDSTART = FALSE",
            f"LDAT_ACT = LCPDAT{self.n}",
            f"FDAT_ACT = F{pname}",
            f"BAS(#CP_PARAMS, {vel})",
            "SET_CD_PARAMS (0)",
        ]
        if kind == "on":
            self.src += [
                f"TRIGGER WHEN DISTANCE = 1 DELAY = ArcGetDelay(#PreDefinition, {wdat}) DO"
                f" ArcMainNG(#PreDefinition, {args}) PRIO = -1",
                f"TRIGGER WHEN PATH = ArcGetPath(#OnTheFlyArcOn, {wdat}) DELAY = ArcGetDelay(#GasPreflow, {wdat}) DO"
                f" ArcMainNG(#GasPreflow, {args}) PRIO = -1",
                f"TRIGGER WHEN PATH = ArcGetPath(#OnTheFlyArcOn, {wdat}) DELAY = 0 DO ArcMainNG(#ArcOnMoveStd,"
                f" {args}) PRIO = -1",
            ]
        elif kind == "swi":
            self.src.append(f"TRIGGER WHEN DISTANCE = 1 DELAY = 0 DO ArcMainNG(#ArcSwiMoveStd, {args}) PRIO = -1")
        else:
            self.src += [
                f"TRIGGER WHEN PATH = ArcGetPath(#ArcOffBefore, {wdat}) DELAY = 0 DO"
                f" ArcMainNG(#ArcOffBeforeOffStd, {args}) PRIO = -1",
                f"TRIGGER WHEN PATH = ArcGetPath(#OnTheFlyArcOff, {wdat}) DELAY = 0 DO ArcMainNG(#ArcOffMoveStd,"
                f" {args}) PRIO = -1",
            ]
        self.src += [
            f"ArcMainNG(#{step}BeforeMoveStd, {args})",
            f"{motion} {xp}" if move is None else move[0],
            f"ArcMainNG(#{step}AfterMoveStd, {args})",
            ";ENDFOLD",
        ]
        self.last_vel = -1.0  # the inline form set the path velocity itself

    def curve_weld(self, seg: Segment, nxt: Segment | None) -> None:
        """A weld along a curve (:func:`cell.export.circles.curve_moves`): each circular move or chord in its own
        ArcTech form (ARC_SWI, the last ARC_OFF, or ARC_SWI into ``nxt``, a next weld), or plain motions then the
        arc off."""
        moves = curve_moves(seg, self.job.robot, base_at(self.job.plan, seg))
        self.src.append(f";- weld along a curve, seam {seg.seam_id}: {len(moves)} moves")
        if self.opt.arc == "arctech":
            for k, mv in enumerate(moves):
                last = k == len(moves) - 1
                kind = "off" if last and nxt is None else "swi"
                self.arc_fold(kind, seg, nxt if last and nxt is not None else seg, self.curve_motion(mv, seg.e1_end))
            return
        if abs(seg.speed - self.last_vel) > 1e-9:
            self.src.append(f"$VEL.CP = {seg.speed:.4f} ; [m/s] {seg.speed * 1000:.1f} mm/s")
            self.last_vel = seg.speed
        for mv in moves:
            self.src.append(f"{self.curve_motion(mv, seg.e1_end)[0]} ; weld, seam {seg.seam_id}")
        if nxt is not None:
            self.src.append(f";- {procedure_line(procedure_of(nxt), nxt.pass_index)} (set on the power source)")
        else:
            self.signal_off(seg)

    def signal_on(self, seg: Segment, p_seg: Segment) -> None:
        """Plain I/O: the arc on at the weld start, the wait for the arc with its timeout and error branch."""
        o, i, ms = self.opt.arc_on_output, self.opt.arc_ok_input, round(self.opt.arc_timeout_s * 1000.0)
        p = procedure_of(p_seg)
        self.src += [
            f";- arc on, seam {seg.seam_id}: set the power source to {p.name} (setup block)",
            f"$OUT[{o}] = TRUE",
            "$TIMER_STOP[1] = TRUE",
            f"$TIMER[1] = -{ms}",
            "$TIMER_STOP[1] = FALSE",
            f"WAIT FOR $IN[{i}] OR $TIMER_FLAG[1]",
            "$TIMER_STOP[1] = TRUE",
            f"IF NOT $IN[{i}] THEN",
            f"  $OUT[{o}] = FALSE",
            f"  HALT ; no arc within {self.opt.arc_timeout_s:g} s at the start of seam {seg.seam_id}: arc off, stopped",
            "ENDIF",
        ]
        if p.crater_start_s > 0.0:
            self.src.append(f"WAIT SEC {num(p.crater_start_s)} ; hot start at rest")

    def signal_off(self, seg: Segment) -> None:
        p = procedure_of(seg)
        if p.crater_end_s > 0.0:
            self.src.append(f"WAIT SEC {num(p.crater_end_s)} ; crater fill at rest")
        self.src.append(f"$OUT[{self.opt.arc_on_output}] = FALSE ; arc off, seam {seg.seam_id}")


def krl_texts(job: ProgramJob) -> tuple[str, str]:
    """(src, dat) texts of the job's program (module docstring)."""
    opt, plan = job.options, job.plan
    b = _Program(job)
    made_by = header_lines(job.provenance) if job.provenance is not None else []
    b.src += [
        "&ACCESS RVP",
        "&REL 1",
        f"DEF {job.name}( )",
        ";- Generated by the weld cell (cell.export.krl)"
        " from a WeldPlan that passed the safety gate; units mm, deg; A, B, C = rotations about Z, Y, X.",
        *made_by,
        *not_welded_lines(job),
        *(track_header(plan.track) if plan.track is not None else []),
        *(positioner_header(job.external, job.X_RB) if job.external is not None else []),
        *setup_block(job),
    ]
    b.dat[1:1] = made_by
    b.dat.append(f"DECL E6AXIS XHOME_PLAN={e6axis(plan.q_home)} ; the planned home (XHOME must equal it)")
    far = " OR ".join(f"(ABS(XHOME.A{i} - XHOME_PLAN.A{i}) > {HOME_TOL_DEG})" for i in range(1, 7))
    if plan.track is not None:  # home is at E1 = 0 too
        far += f" OR (ABS(XHOME.E1 - XHOME_PLAN.E1) > {HOME_TOL_MM})"
    b.src += [
        ";FOLD INI", ";FOLD BASISTECH INI", "GLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM ( )",
        "INTERRUPT ON 3", "BAS(#INITMOV, 0)", ";ENDFOLD (BASISTECH INI)", ";FOLD USER INI", ";ENDFOLD (USER INI)",
        ";ENDFOLD (INI)", "",
        f"BAS(#TOOL, {opt.tool_index})", *base_lines(job),
        f"BAS(#VEL_PTP, {opt.ptp_percent})", f"BAS(#ACC_PTP, {opt.ptp_percent})",
        f"IF {far} THEN",
        "  HALT ; $config.dat's XHOME is not the planned home XHOME_PLAN (setup block): correct it first",
        "ENDIF",
        "$H_POS = XHOME",
        "PTP XHOME ; first motion: fully defined axis point (block coincidence)",
        *positioner_move(b, job),
    ]  # fmt: skip
    segs = plan.segments
    current = ""
    for k, seg in enumerate(segs):
        nxt = segs[k + 1] if k + 1 < len(segs) else None
        if seg.seam_id and seg.seam_id != current:
            current = seg.seam_id
            b.src += ["", f";- seam {current}"]
        arc_next = nxt is not None and nxt.kind == "weld"
        if seg.kind == "weld" and seg.X_path is not None:
            b.curve_weld(seg, nxt if arc_next else None)
            continue
        if seg.kind == "weld":
            if opt.arc == "arctech":
                b.arc_fold("swi" if arc_next and nxt is not None else "off", seg, nxt if arc_next and nxt else seg)
                continue
            b.plain_lin(seg, f"weld, seam {seg.seam_id}")
            if nxt is not None and arc_next:
                b.src.append(f";- {procedure_line(procedure_of(nxt), nxt.pass_index)} (set on the power source)")
            else:
                b.signal_off(seg)
            continue
        if seg.kind == "move" and nxt is None and np.allclose(seg.trajectory.q[-1], plan.q_home, atol=1e-9):
            b.src += ["", "PTP XHOME ; back home"]
            continue
        if arc_next and nxt is not None and opt.arc == "arctech":
            b.arc_fold("on", seg, nxt)
            continue
        if seg.kind == "move":
            e1 = seg.trajectory.e1
            moves = e1 is not None and float(np.ptp(e1)) > 0.0  # the carriage moves (the arm with it, or at home)
            track = f" (track to E1 = {seg.e1_end * 1000:.1f} mm)" if moves else ""
            c_dis = b.approx(seg)
            b.src.append(f"PTP {b.point(seg)}{c_dis} ; transfer{track}")
        else:
            b.plain_lin(seg, "approach, exact stop at the weld start" if arc_next else seg.kind)
        if arc_next and nxt is not None:
            b.signal_on(nxt, nxt)
    b.src += ["END", ""]
    b.dat += ["ENDDAT", ""]
    return "\n".join(b.src), "\n".join(b.dat)


class KrlPost:
    """The KUKA KRL post-processor (:class:`~cell.export.program.PostProcessor`): ``NAME.src`` and ``NAME.dat``."""

    name = "krl"

    def texts(self, job: ProgramJob) -> dict[str, str]:
        src, dat = krl_texts(job)
        return {f"{job.name}.src": src, f"{job.name}.dat": dat}


def krl_program(
    plan: WeldPlan,
    robot: Kinematics,
    name: str,
    *,
    X_RB: npt.ArrayLike | None = None,
    X_WR: npt.ArrayLike | None = None,
    options: KrlOptions | None = None,
    provenance: Mapping[str, Any] | None = None,
) -> tuple[str, str]:
    """(src, dat) texts of the program ``name`` for ``plan`` (:class:`~cell.types.plan.WeldPlan`).

    X_RB : (4, 4) the part's base in R (default: the identity, the base is $ROBROOT).
    X_WR : (4, 4) the robot's mounting in the cell's world, only written as a comment.
    Raises ValueError for an invalid name or a plan without motion.
    """
    job = ProgramJob(
        plan, robot, name, X_RB=np.eye(4) if X_RB is None else np.asarray(X_RB, dtype=float),
        X_WR=None if X_WR is None else np.asarray(X_WR, dtype=float), options=options or KrlOptions(),
        provenance=provenance,
    )  # fmt: skip
    return krl_texts(job)


def write_krl(
    plan: WeldPlan,
    robot: Kinematics,
    directory: str | Path,
    name: str,
    *,
    X_RB: npt.ArrayLike | None = None,
    X_WR: npt.ArrayLike | None = None,
    options: KrlOptions | None = None,
    provenance: Mapping[str, Any] | None = None,
) -> tuple[Path, Path]:
    """Write ``NAME.src`` and ``NAME.dat`` (upper-case name, CRLF line ends, each file atomically); their paths.
    OutputError when a file cannot be written."""
    src, dat = krl_program(plan, robot, name, X_RB=X_RB, X_WR=X_WR, options=options, provenance=provenance)
    up = name.upper()
    paths = write_texts({f"{up}.src": src, f"{up}.dat": dat}, directory)
    return paths[0], paths[1]
