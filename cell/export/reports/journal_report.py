"""Reports from the job journal (docs/journal.md): the report of a job stopped on the way, every stage and every
weld the journal holds; and a finished run's report joined with what earlier runs of the same job welded, each
seam naming the run that welded it."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from cell.journal import JobState

_REASONS = {"not_visible": "not_visible", "found": "not_executed"}  # a seam not welded: why, by its located status


def journal_seams(state: JobState) -> list[dict[str, Any]]:
    """One entry per seam the journal located (map order, side A first): its side, status, whether and by which
    run it was welded (arc times, TCP error), or why not: ``interrupted`` (its arc went on and the journal ends
    before it went off: a bead stopped part way, not welded), ``not_executed`` (located, not reached),
    ``not_visible``, ``not_located``."""
    seen: dict[str, Mapping[str, Any]] = {}
    side: dict[str, str] = {}
    for rec in state.records:
        if rec.get("kind") != "located":
            continue
        for s in rec.get("seams", []):
            if s["id"] not in seen or s["status"] == "found":
                seen[s["id"]], side[s["id"]] = s, str(rec.get("side", "A"))
    out = []
    for sid, s in seen.items():
        w = state.welds.get(sid)
        e: dict[str, Any] = {"id": sid, "side": w.side if w is not None else side[sid], "status": s["status"]}
        e["reason_code"] = s.get("reason_code")
        e["confidence"] = s.get("confidence")
        e["planned"] = w is not None or _planned(state, sid)
        e["welded"] = w is not None
        if w is not None:
            e.update(run=w.run, arc_on_s=w.t_on_s, arc_off_s=w.t_off_s, length_mm=w.length_mm)
            e.update(tcp_error_mm={"rms": w.tcp_rms_mm, "max": w.tcp_max_mm}, weld_reason_code=None, weld_reason="")
            e["weld_time_s"] = (
                round(w.t_off_s - w.t_on_s, 3) if w.t_on_s is not None and w.t_off_s is not None else None
            )
        elif sid in state.interrupted:
            i = state.interrupted[sid]
            e.update(run=i.run, arc_on_s=i.t_on_s, weld_reason_code="interrupted")
            e["weld_reason"] = f"interrupted: the arc went on at {i.t_on_s} s in run {i.run}; no arc off recorded"
        else:
            e["run"] = None
            e["weld_reason_code"] = _REASONS.get(s["status"], "not_located")
            e["weld_reason"] = "the job stopped before it" if s["status"] == "found" else s["status"]
        out.append(e)
    return out


def _planned(state: JobState, seam: str) -> bool:
    return any(r.get("kind") == "planned" and seam in r.get("order", ()) for r in state.records)


def stopped_job_report(state: JobState, base: Mapping[str, Any]) -> dict[str, Any]:
    """The report of a job stopped on the way: ``base`` (the keys every stopped report has: scenario, provenance,
    ``interrupted``, ``error``) with the journal's seams, ``welded``, the turn (``flip``), the stages reached and
    the ``journal`` block."""
    rep = dict(base)
    rep["seams"] = journal_seams(state)
    rep["welded"] = sum(bool(e["welded"]) for e in rep["seams"])
    rep["flip"] = _turn(state)
    rep["stages"] = stages(state)
    rep["journal"] = journal_block(state)
    return rep


def joined_report(rep: Mapping[str, Any], state: JobState, run: str, *, on_b: bool) -> dict[str, Any]:
    """A finished run's report (this ``run``'s) with the seams earlier runs of its job welded, from the journal:
    each seam's ``run``; ``welded`` counts every run's; ``on_b``: this run welded side B only (a resume after the
    turn)."""
    out = dict(rep)
    mine = {e["id"]: dict(e) for e in rep.get("seams", [])}
    for e in mine.values():
        if on_b and e.get("side") is not None:
            e["side"] = "B"
        e["run"] = run if e.get("welded") else None
    earlier = {e["id"]: e for e in journal_seams(state) if e["welded"] and e["run"] != run}
    seams = []
    for e in journal_seams(state):  # the job's seams in the journal's order
        seams.append(earlier.get(e["id"]) or mine.pop(e["id"], e))
    seams += list(mine.values())
    out["seams"] = seams
    out["welded"] = sum(bool(e.get("welded")) for e in seams)
    before = sum(e["id"] in earlier for e in seams)
    if before and isinstance(out.get("summary"), Mapping):  # the part's counts: the earlier runs' seams too
        out["summary"] = {**out["summary"]}
        for key in ("seams", "visible", "found"):
            out["summary"][key] = out["summary"].get(key, 0) + before
    out["journal"] = journal_block(state)
    if on_b:  # this run is side B's: the turn is an earlier run's
        out["flip"] = out.get("flip") or _turn(state)
        sides = list(out.get("sides", {}).values())
        out["sides"] = {"B": sides[0]} if sides else {}
    return out


def stages(state: JobState) -> list[dict[str, Any]]:
    """The steps the journal holds, one per record but the header and the arc switches: run, kind, side."""
    skip = {"journal", "arc_on", "arc_off"}
    return [
        {"run": r.get("run"), "kind": r.get("kind"), "side": r.get("side")}
        for r in state.records
        if r.get("kind") not in skip
    ]


def journal_block(state: JobState) -> dict[str, Any]:
    """Where the journal is and the runs of the job it holds."""
    return {"path": str(state.path), "runs": list(state.runs), "warnings": list(state.warnings)}


def _turn(state: JobState) -> dict[str, Any] | None:
    t = state.turn
    if t is None:
        return None
    return {
        "made": True,
        "axis": t.get("axis"),
        "rotation_deg": t.get("rotation_deg"),
        "tilt_deg": t.get("tilt_deg"),
        "exposed": t.get("exposed"),
        "run": t.get("run"),
        "placement_error_mm": None,  # measured by side B's alignment: in its ``located`` record's X_RM
        "placement_rotation_deg": None,
        "fitness": None,
    }
