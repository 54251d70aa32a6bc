"""The last line of stderr when a run is partial (exit 3): why, from the report, so screen and file agree.

For example ``exit 3: camera cam_left lost (no valid pixels); 12/12 welded`` or
``exit 3: 2 seams not welded (low_confidence: 1, not_planned: 1); 10/12 welded`` or
``exit 3: 1 seam not supported (curved: 1); 2/2 welded`` or
``exit 3: 1 curved seam partly welded: 21 mm left for a manual weld; 2/3 welded``.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from typing import Any

from cell.errors import EXIT_PARTIAL
from cell.types.run import partial_text


def _counted(counts: Counter[str]) -> str:
    return ", ".join(f"{code}: {n}" for code, n in sorted(counts.items()))


def _lost(rep: Mapping[str, Any]) -> list[str]:
    out = []
    for entry in rep.get("lost_cameras") or ():
        name, _, why = str(entry).partition(": ")
        out.append(f"camera {name} lost ({why})" if why else f"camera {name} lost")
    return out


def _error(rep: Mapping[str, Any]) -> list[str]:
    e = rep.get("error")
    return [str(e["message"])] if isinstance(e, Mapping) and e.get("message") else []


def _undetected(rep: Mapping[str, Any]) -> list[str]:
    """Visible seams not found, by status and reason code."""
    parts = []
    for status in ("occluded", "not_found"):
        codes = Counter(str(s.get("reason_code") or "?") for s in rep["seams"] if s["status"] == status)
        n = sum(codes.values())
        if n:
            parts.append(f"{n} seam{'s' * (n != 1)} {status.replace('_', ' ')} ({_counted(codes)})")
    return parts


def _unsupported(rep: Mapping[str, Any]) -> list[str]:
    """Seams of the map the cell cannot weld, by reason code."""
    codes = Counter(str(s.get("reason_code") or "?") for s in rep["seams"] if s["status"] == "not_supported")
    n = sum(codes.values())
    return [f"{n} seam{'s' * (n != 1)} not supported ({_counted(codes)})"] if n else []


def detection_exit(rep: Mapping[str, Any]) -> str:
    """Why ``cell detect`` (or ``cell rescan``) exits 3: the error, lost cameras, seams not found, seams the cell
    cannot weld; the count."""
    parts = _error(rep) + _lost(rep) + _undetected(rep) + _unsupported(rep)
    m = rep["summary"]
    return f"exit {EXIT_PARTIAL}: {'; '.join(parts) or 'partial result'}; {m['found']}/{m['visible']} visible found"


def weld_exit(rep: Mapping[str, Any]) -> str:
    """Why ``cell weld`` (or ``cell preview``) exits 3: the error, lost cameras, seams not welded by reason code,
    curved seams welded in part, seams the cell cannot weld; then how many visible seams were welded (planned, for
    a preview)."""
    visible = [s for s in rep["seams"] if s["status"] not in ("not_visible", "not_supported")]
    preview = not any(s["welded"] for s in visible) and any(s.get("weld_reason_code") == "preview" for s in visible)
    if preview:
        undone = Counter(str(s.get("weld_reason_code")) for s in visible if not s.get("planned"))
    else:
        undone = Counter(str(s.get("weld_reason_code") or "?") for s in visible if not s["welded"])
    part = undone.pop("partial", 0)  # curves welded in part: said apart, with what is left for a manual weld
    n = sum(undone.values())
    verb = "planned" if preview else "welded"
    parts = _error(rep) + _lost(rep) + ([f"{n} seam{'s' * (n != 1)} not {verb} ({_counted(undone)})"] if n else [])
    if part:
        parts.append(partial_text(part, (rep["summary"].get("curved") or {}).get("manual_mm")))
    parts += _unsupported(rep)
    done = sum(bool(s.get("planned")) for s in visible) if preview else rep["welded"]
    return f"exit {EXIT_PARTIAL}: {'; '.join(parts) or 'partial result'}; {done}/{len(visible)} {verb}"
