"""One run of a sweep: build the varied scenario, run the pipeline to the sweep's stage and say per seam what became
of it, as plain JSON values in millimetres, rounded so a run's line is the same bytes wherever it ran. A run never
raises: a failure is its ``error``."""

from __future__ import annotations

import time
import traceback
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from cell.errors import CellError
from cell.scenario import Scenario
from cell.sweep.variations import Variation, varied
from cell.types.run import WeldReason

if TYPE_CHECKING:
    from cell.pipeline import Detection, WeldRun

Stage = Literal["detect", "plan", "weld"]
STAGES: tuple[Stage, ...] = ("detect", "plan", "weld")
_MM = 1000.0
_DIGITS = 4  # [mm]: 0.1 um, far below any figure a sweep reports, far above a floating-point last bit


def _mm(v: float | None) -> float | None:
    """A length [mm] rounded for the line (None and NaN become None: JSON has no NaN)."""
    if v is None or not np.isfinite(v):
        return None
    return round(float(v), _DIGITS)


def run_task(scenario: Scenario, v: Variation, stage: Stage, method: str | None = None) -> dict[str, Any]:
    """Run ``v`` of a sweep of ``scenario`` to ``stage``. Returns ``{"line": ..., "timings": ...}``: the line is
    what runs.jsonl keeps (run index, the variation, per seam its figures, the error or None), the timings [s]
    are kept apart (they differ from one machine and one run to the next)."""
    t0 = time.perf_counter()
    line: dict[str, Any] = {"run": v.k, "variation": v.to_json(), "seams": {}, "error": None}
    timings: dict[str, float] = {}
    try:
        sc = varied(scenario, v)
        if stage == "detect":
            from cell.pipeline import detect

            det = detect(sc, method)
            line["seams"] = detection_seams(det, sc)
            timings = dict(det.timings)
            if det.error is not None:
                line["error"] = error_json(det.error)
        else:
            from cell.pipeline import WeldJob, weld

            run = weld(sc, WeldJob(method, execute=stage == "weld"))
            line["seams"] = weld_seams(run, sc, stage)
            timings = dict(run.timings)
            if run.error is not None:
                line["error"] = error_json(run.error)
    except Exception as e:
        line["seams"] = {}
        line["error"] = error_json(e)
        line["error"]["traceback"] = traceback.format_exc(limit=8)
    timings["task_s"] = time.perf_counter() - t0
    return {"line": line, "timings": {k: round(t, 3) for k, t in timings.items()}}


def error_json(e: BaseException) -> dict[str, Any]:
    """An error as JSON: its class, one-line message and the exit code the CLI gives it (1: not the cell's)."""
    code = e.exit_code if isinstance(e, CellError) else 1
    msg = e.message if isinstance(e, CellError) else " ".join(str(e).split()) or type(e).__name__
    return {"type": type(e).__name__, "message": msg, "exit_code": code}


def detection_seams(det: Detection, sc: Scenario) -> dict[str, dict[str, Any]]:
    """Per seam of a detection: status, found, lateral and endpoint error [mm] against the truth, sigma [mm],
    within the weld tolerance (found and the lateral error at most ``rescan.weld_tolerance_mm``), the reason."""
    tol = sc.rescan.weld_tolerance_mm
    out: dict[str, dict[str, Any]] = {}
    for e in det.estimates:
        m = det.metrics.get(e.id)
        found = m is not None and m.found
        lateral = m.lateral_mm if found and m is not None else None
        out[e.id] = {
            "status": e.status.value,
            "found": bool(found),
            "lateral_mm": _mm(lateral),
            "endpoint_mm": _mm(m.endpoint_mm if found and m is not None else None),
            "sigma_mm": _mm(e.sigma_m * _MM) if found else None,
            "within_tolerance": bool(found and lateral is not None and lateral <= tol),
            "reasons": [e.reason] if e.reason else [],
        }
    return out


def weld_seams(run: WeldRun, sc: Scenario, stage: Stage) -> dict[str, dict[str, Any]]:
    """Per seam of a weld run: the detection's figures (after the re-scan for ``weld``), then for ``plan``:
    ``planned`` (feasible and the gate passed) and ``plan_tcp_rms_mm`` (the planned torch path's TCP against the
    true seam); for ``weld``: ``planned``, ``welded`` and ``weld_rms_mm`` (the executed TCP against the true
    seam, all passes)."""
    out = detection_seams(run.detection, sc)
    planned_tcp = _planned_tcp_rms(run) if stage == "plan" else {}
    for w in run.seams:
        rec = out.setdefault(w.id, {"found": False, "reasons": []})
        code = w.code.value if w.code is not None else None
        if stage == "plan":
            rec["planned"] = bool(w.planned and w.code is WeldReason.PREVIEW)
            rec["plan_tcp_rms_mm"] = _mm(planned_tcp.get(w.id))
        else:
            rec["planned"] = bool(w.planned)
            rec["welded"] = bool(w.welded)
            rec["weld_rms_mm"] = _mm(w.quality.tcp_rms_mm) if w.quality is not None else None
        rec["code"] = code
        # a preview's words say nothing, and an unseen or unlocated seam's repeat the estimate's reason
        repeats = w.code in (WeldReason.NOT_VISIBLE, WeldReason.NOT_LOCATED) and rec["reasons"]
        if w.reason and w.code is not WeldReason.PREVIEW and not repeats:
            rec["reasons"] = [*rec["reasons"], w.reason]
    return out


def _planned_tcp_rms(run: WeldRun, every: int = 20) -> dict[str, float]:
    """Per planned seam: RMS distance [mm] of the planned TCP (every ``every``-th 1 kHz sample of its root pass)
    from the true seam segment. Seams whose procedure weaves are left out (the weave is meant to leave the line)."""
    from cell.process.quality import distance_to_segment

    if run.plan is None or run.arm is None:
        return {}
    model = run.arm.model
    d: dict[str, list[float]] = {}
    for seg in run.plan.segments:
        truth = run.detection.truths.get(seg.seam_id)
        if not seg.arc_on or seg.pass_index != 0 or truth is None:
            continue
        if seg.procedure is not None and seg.procedure.weave.active:
            continue
        q = seg.trajectory.q
        p_R = np.array([model.fk(q[i])[:3, 3] for i in range(0, len(q), every)])
        d.setdefault(seg.seam_id, []).extend(distance_to_segment(p_R, truth[0], truth[1]).tolist())
    return {s: float(np.sqrt(np.mean(np.square(v)))) * _MM for s, v in d.items() if v}
