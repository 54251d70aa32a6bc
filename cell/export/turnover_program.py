"""A job of several sides (the part turned over between them) as one robot program: each side's program and a main
program that calls them with an operator stop between (KRL and RAPID; docs/programs.md)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Literal

import numpy as np

from cell.export.krl import HOME_TOL_DEG
from cell.export.krl_data import e6axis, main_ini
from cell.export.post import post_processor
from cell.export.program import _NAME, ProgramJob, not_welded_lines, write_texts
from cell.provenance import header_lines

StopKind = Literal["message", "halt"]
MESSAGE_MAX = 80  # KRL KrlMsg_T.Msg_Txt[] and RAPID's TPWrite / TPReadFK text: at most 80 characters
_MESSAGE = re.compile(r"[ -~]*")  # printable ASCII
MESSAGE_NR = 1  # the message number the KRL acknowledgement message shows
HOME_TOL_E1_MM = 0.5  # the home guard's tolerance on a linear track's E1 [mm], as a side program's


def _check(controller: str, jobs: Sequence[ProgramJob], main_name: str, turnover_message: str, stop: str) -> str:
    """The main program's upper-case name after checking the arguments; ValueError (one line) when one is wrong."""
    post_processor(controller)  # ValueError naming the valid controllers
    if controller not in ("krl", "rapid"):
        raise ValueError(f"controller {controller!r} has no main program here; valid: krl, rapid")
    if not jobs:
        raise ValueError("no side to write: a two-sided program needs at least one job")
    if not _NAME.fullmatch(main_name):
        raise ValueError(
            f"main program name {main_name!r} is invalid: 1-24 characters, a letter or _ first, then letters, digits, _"
        )
    main = main_name.upper()
    seen: set[str] = set()
    for job in jobs:
        if job.name == main:
            raise ValueError(f"side program {job.name} has the main program's name; give the sides their own names")
        if job.name in seen:
            raise ValueError(f"two sides are both called {job.name}; each side needs its own program name")
        seen.add(job.name)
    if (
        len(turnover_message) > MESSAGE_MAX
        or not _MESSAGE.fullmatch(turnover_message)
        or set('"\\') & set(turnover_message)
    ):
        raise ValueError(
            f"turnover message {turnover_message[:40]!r}... is invalid: at most {MESSAGE_MAX} printable ASCII"
            " characters without a double quote or backslash"
        )
    if not turnover_message.strip():
        raise ValueError("the turnover message is empty: say what the operator must do before the next side")
    if stop not in ("message", "halt"):
        raise ValueError(f"stop {stop!r} is unknown; valid: message, halt")
    q0 = jobs[0].plan.q_home
    for job in jobs[1:]:
        off = float(np.max(np.abs(np.degrees(np.asarray(job.plan.q_home) - q0))))
        if off > HOME_TOL_DEG:
            raise ValueError(
                f"side {job.name}'s home differs from {jobs[0].name}'s by {off:.2f} deg: every side must plan the"
                f" same home (within {HOME_TOL_DEG} deg), the controller has one"
            )
    return main


def _own_bases(jobs: Sequence[ProgramJob]) -> list[ProgramJob]:
    """The KRL jobs with one BASE_DATA index per distinct base: side k gets the first side's index + k when the
    sides share an index but not the pose (module docstring)."""
    indices = {j.options.base_index for j in jobs}
    same_pose = all(np.allclose(j.X_RB, jobs[0].X_RB, atol=1e-9) for j in jobs)
    if len(indices) == len(jobs) or same_pose:
        return list(jobs)
    first = jobs[0].options.base_index
    return [replace(j, options=replace(j.options, base_index=first + k)) for k, j in enumerate(jobs)]


def _krl_stop(main: str, after: str, before: str, message: str, stop: StopKind) -> list[str]:
    """The .src lines between side ``after`` and side ``before``: the operator's stop (module docstring)."""
    if stop == "halt":
        return [
            f";- operator stop: {after} done, {before} next; press Start once the part is turned",
            f"HALT ; {message}",
        ]
    return [
        f";FOLD OPERATOR STOP: {after} done, {before} next (acknowledgement message, waits for OK)",
        "FLIP_PAR[1] = {PAR_TYPE #EMPTY}",
        "FLIP_PAR[2] = {PAR_TYPE #EMPTY}",
        "FLIP_PAR[3] = {PAR_TYPE #EMPTY}",
        "FLIP_HANDLE = Set_KrlMsg(#QUIT, FLIP_MSG, FLIP_PAR[ ], FLIP_OPT)",
        "IF FLIP_HANDLE == -1 THEN",
        f"  HALT ; the message could not be shown: {message}",
        "ENDIF",
        "WHILE Exists_KrlMsg(FLIP_HANDLE)",
        "  WAIT SEC 0.1",
        "ENDWHILE",
        ";ENDFOLD",
    ]


def krl_main_texts(main: str, jobs: Sequence[ProgramJob], message: str, stop: StopKind) -> tuple[str, str]:
    """(src, dat) of the KRL main program ``main`` calling ``jobs`` in order (module docstring)."""
    first = jobs[0]
    opt = first.options
    made_by = header_lines(first.provenance) if first.provenance is not None else []
    names = ", ".join(j.name for j in jobs)
    far = " OR ".join(f"(ABS(XHOME.A{i} - XHOME_PLAN.A{i}) > {HOME_TOL_DEG})" for i in range(1, 7))
    if getattr(first.plan, "track", None) is not None:  # on a linear track, home is at E1 = 0 too (docs/track.md)
        far += f" OR (ABS(XHOME.E1 - XHOME_PLAN.E1) > {HOME_TOL_E1_MM})"
    src = [
        "&ACCESS RVP",
        "&REL 1",
        f"DEF {main}( )",
        f";- Generated by the weld cell (cell.export.turnover_program): the part's sides in order ({names}), the"
        " operator turning the part between two sides.",
        *made_by,
        *not_welded_lines(first),
        *main_ini(opt, far, "sides"),
    ]  # fmt: skip
    for k, job in enumerate(jobs):
        if k:
            src += ["", *_krl_stop(main, jobs[k - 1].name, job.name, message, stop)]
        seams = list(dict.fromkeys(s.seam_id for s in job.plan.segments if s.kind == "weld" and s.seam_id))
        src += ["", f";- side {k + 1} of {len(jobs)}: {job.name}, seams {', '.join(seams) or '-'}", f"{job.name}( )"]
    src += ["", "PTP XHOME ; back home", "END", ""]
    dat = [f"DEFDAT {main} PUBLIC", *made_by]
    dat.append(f"DECL E6AXIS XHOME_PLAN={e6axis(first.plan.q_home)} ; the planned home (XHOME must equal it)")
    if stop == "message" and len(jobs) > 1:
        dat += [
            f'DECL KrlMsg_T FLIP_MSG={{Modul[] "{main}",Nr {MESSAGE_NR},Msg_Txt[] "{message}"}}',
            "DECL KrlMsgPar_T FLIP_PAR[3]",
            "DECL KrlMsgOpt_T FLIP_OPT={VL_Stop TRUE,Clear_P_Reset TRUE,Clear_P_SAW FALSE,Log_To_DB TRUE}",
            "DECL INT FLIP_HANDLE=0",
        ]
    dat += ["ENDDAT", ""]
    return "\n".join(src), "\n".join(dat)


def _rapid_side(text: str, name: str) -> str:
    """A side's RAPID module with its data LOCAL and its ``main`` routine renamed ``NAME_RUN``."""
    text = re.sub(r"^  (PERS|CONST|VAR) ", r"  LOCAL \1 ", text, flags=re.M)
    return re.sub(r"^  PROC main\(\)$", f"  PROC {name}_RUN()", text, count=1, flags=re.M)


def rapid_main_text(main: str, jobs: Sequence[ProgramJob], side_texts: Sequence[str], message: str,
                    stop: StopKind) -> str:  # fmt: skip
    """The RAPID main module ``main`` calling ``jobs`` in order (module docstring)."""
    first = jobs[0]
    tool = re.search(r"^  PERS tooldata tWeld := (.*);$", side_texts[0], flags=re.M)
    home = re.search(r"^  CONST jointtarget jHome := (.*);$", side_texts[0], flags=re.M)
    if tool is None or home is None:  # the RAPID post always writes both: a change there must change this
        raise RuntimeError("the RAPID side module has no tWeld tooldata or jHome jointtarget to copy")
    names = ", ".join(j.name for j in jobs)
    lines = ["%%%", "  VERSION:1", "  LANGUAGE:ENGLISH", "%%%", "", f"MODULE {main}"]
    lines += [f"  ! Generated by the weld cell (cell.export.turnover_program): the part's sides in order ({names}),"]
    lines += ["  ! the operator turning the part between two sides."]
    lines += header_lines(first.provenance, prefix="  ! ") if first.provenance is not None else []
    lines += not_welded_lines(first, prefix="  ! ")
    lines += [
        f"  LOCAL PERS tooldata tWeld := {tool.group(1)};",
        f"  LOCAL CONST jointtarget jHome := {home.group(1)};",
        "",
        "  PROC main()",
        "    VAR num nKey;",
        "    ConfJ \\On;",
        "    MoveAbsJ jHome, v1000, fine, tWeld;",
    ]
    for k, job in enumerate(jobs):
        if k:
            before, after = job.name, jobs[k - 1].name
            lines += [f"    ! operator stop: {after} done, {before} next", "    TPErase;"]
            if stop == "halt":
                lines += [f'    TPWrite "{message}";', "    Stop;"]
            else:
                lines += [
                    f'    TPWrite "{after} done, {before} next";',
                    f'    TPReadFK nKey, "{message}", "Turned", stEmpty, stEmpty, stEmpty, "Abort";',
                    "    IF nKey <> 1 THEN",
                    f'      TPWrite "Aborted by the operator: {before} not welded";',
                    "      EXIT;",
                    "    ENDIF",
                ]
        lines += [f"    ! side {k + 1} of {len(jobs)}", f"    {job.name}_RUN;"]
    lines += ["    MoveAbsJ jHome, v1000, fine, tWeld;", "  ENDPROC", "ENDMODULE", ""]
    return "\n".join(lines)


def turnover_program(
    controller: str,
    jobs: Sequence[ProgramJob],
    *,
    main_name: str,
    turnover_message: str,
    stop: StopKind = "message",
) -> dict[str, str]:
    """Every text of a job of several sides: each side's own texts from ``controller``'s post (``krl`` or
    ``rapid``) and the main program ``main_name`` calling them in order with the operator's stop (``message``, the
    default, or ``halt``) between two sides, showing ``turnover_message`` (module docstring). One job: just its texts.

    ValueError (one line) for an unknown controller, an invalid or clashing name, a message over 80 characters
    (or not printable ASCII, or with a double quote), or sides that plan different homes.
    """
    main = _check(controller, jobs, main_name, turnover_message, stop)
    post = post_processor(controller)
    if len(jobs) == 1:
        return post.texts(jobs[0])
    texts: dict[str, str] = {}
    if controller == "rapid":
        sides = [post.texts(j)[f"{j.name}.mod"] for j in jobs]
        texts[f"{main}.mod"] = rapid_main_text(main, jobs, sides, turnover_message, stop)
        texts.update((f"{j.name}.mod", _rapid_side(t, j.name)) for j, t in zip(jobs, sides, strict=True))
        return texts
    jobs = _own_bases(jobs)
    src, dat = krl_main_texts(main, jobs, turnover_message, stop)
    texts[f"{main}.src"], texts[f"{main}.dat"] = src, dat
    for job in jobs:
        texts.update(post.texts(job))
    return texts


def write_turnover_program(
    controller: str,
    jobs: Sequence[ProgramJob],
    main_name: str,
    turnover_message: str,
    directory: str | Path,
    *,
    stop: StopKind = "message",
) -> list[Path]:
    """Write :func:`turnover_program`'s texts into ``directory`` (each file atomically, CRLF line ends); their
    paths, the main program's first. ValueError as there; OutputError when a file cannot be written."""
    texts = turnover_program(controller, jobs, main_name=main_name, turnover_message=turnover_message, stop=stop)
    return write_texts(texts, directory)
