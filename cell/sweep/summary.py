"""A sweep's summary (``summary.json``): per seam how often it was found, within the weld tolerance, planned and
welded, and its errors' percentiles, from the runs' lines; a failed run counts in no seam's probability."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

PERCENTILES = (50, 90, 99)
ERRORS = ("lateral_mm", "endpoint_mm", "sigma_mm", "plan_tcp_rms_mm", "weld_rms_mm")  # figures summarised


def percentiles(values: Sequence[float]) -> dict[str, float] | None:
    """p50, p90, p99 and max [the values' unit] (None without values)."""
    if not values:
        return None
    a = np.asarray(values, dtype=float)
    out = {f"p{p}": round(float(np.percentile(a, p)), 4) for p in PERCENTILES}
    out["max"] = round(float(a.max()), 4)
    return out


def _share(flags: Sequence[bool]) -> float | None:
    return round(sum(flags) / len(flags), 4) if flags else None


def seam_summary(recs: Sequence[Mapping[str, Any]], stage: str) -> dict[str, Any]:
    """One seam over the runs that have it: the probabilities, the error percentiles of the runs that found it,
    the three most frequent reasons it was not found, planned or welded (numbers stripped, so the same cause
    counts once)."""
    out: dict[str, Any] = {
        "runs": len(recs),
        "probability_found": _share([bool(r.get("found")) for r in recs]),
        "probability_within_tolerance": _share([bool(r.get("within_tolerance")) for r in recs]),
        "probability_planned": _share([bool(r.get("planned")) for r in recs]) if stage != "detect" else None,
        "probability_welded": _share([bool(r.get("welded")) for r in recs]) if stage == "weld" else None,
    }
    for name in ERRORS:
        vals = [float(r[name]) for r in recs if r.get(name) is not None]
        if vals or name in ("lateral_mm", "endpoint_mm"):
            out[name] = percentiles(vals)
    reasons: Counter[str] = Counter()
    for r in recs:
        if not _undone(r, stage):  # a seam found and planned (welded) has notes, not reasons
            continue
        for why in r.get("reasons", ()):
            reasons[_gist(why)] += 1
    out["reasons"] = [{"reason": why, "runs": n} for why, n in reasons.most_common(3)]
    return out


def _undone(rec: Mapping[str, Any], stage: str) -> bool:
    """The seam was not found, or (plan, weld) not planned, or (weld) not welded in this run."""
    if not rec.get("found"):
        return True
    return (stage != "detect" and not rec.get("planned")) or (stage == "weld" and not rec.get("welded"))


def _brief(error: Mapping[str, Any] | None) -> dict[str, Any]:
    """A failed run's error without its traceback (runs.jsonl keeps it)."""
    if not error:
        return {"message": "no seam figures"}
    return {k: v for k, v in error.items() if k != "traceback"}


def _gist(reason: str) -> str:
    """A reason without its numbers (``bound 3 sigma = 0.61 mm > ...`` and ``... = 0.72 mm`` are one cause)."""
    words = [("#" if any(ch.isdigit() for ch in w) else w) for w in reason.split()]
    return " ".join(words)[:160]


def summarize(
    lines: Iterable[Mapping[str, Any]],
    seam_ids: Sequence[str],
    *,
    n: int,
    stage: str,
    engine: Mapping[str, Any],
    sweep: Mapping[str, Any],
    weld_tolerance_mm: float,
) -> dict[str, Any]:
    """``summary.json``: the engine, the sweep's parameters, runs asked (``n``), done, failed (and their errors),
    per seam (map order, then any seam only the runs know) its :func:`seam_summary`. Only runs 0 .. n-1 count."""
    runs = sorted((ln for ln in lines if int(ln["run"]) < n), key=lambda ln: int(ln["run"]))
    failed = [ln for ln in runs if not ln.get("seams")]
    ok = [ln for ln in runs if ln.get("seams")]
    ids = list(seam_ids) + sorted({s for ln in ok for s in ln["seams"]} - set(seam_ids))
    seams = {}
    for sid in ids:
        recs = [ln["seams"][sid] for ln in ok if sid in ln["seams"]]
        seams[sid] = seam_summary(recs, stage)
    return {
        **dict(engine),
        "sweep": dict(sweep),
        "stage": stage,
        "weld_tolerance_mm": weld_tolerance_mm,
        "n": n,
        "done": len(runs),
        "failed": len(failed),
        "failed_runs": [{"run": ln["run"], **_brief(ln.get("error"))} for ln in failed],
        "run_errors": dict(Counter(_gist(ln["error"]["message"]) for ln in ok if ln.get("error"))),
        "seams": seams,
    }
