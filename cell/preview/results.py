"""The results table of a run: one row per seam, read from the run's seam records (values only).

Columns: seam, status, the locator's sigma [mm], the error against the true seam when the truth is known [mm],
welded (or planned) or why not, the torch's work and travel angles [deg]. :func:`results_rows` gives the cells as
text, :func:`results_table` an HTML ``<table>`` of them; the map's seams the cell cannot weld (a curve) follow, with
status ``not_supported`` and their reason.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence

from cell.types import SeamRecord, SeamStatus, UnsupportedSeam
from cell.types.run import SeamWeld

COLUMNS = ("seam", "status", "sigma [mm]", "error [mm]", "weld", "work angle [deg]", "travel angle [deg]")


def _mm(v: float) -> str:
    return f"{v * 1000.0:.2f}" if math.isfinite(v) else "–"


def _deg(v: float) -> str:
    return f"{math.degrees(v):.1f}" if math.isfinite(v) else "–"


def _weld(rec: SeamRecord) -> tuple[str, str]:
    """What became of the seam (``welded``, ``planned`` or the reason's code) and the detail."""
    w = rec.weld
    if w is None:
        return "–", ""
    if w.welded:
        q = w.quality
        return "welded", "" if q is None else f"TCP {q.tcp_rms_mm:.2f} mm RMS from the true seam"
    if w.code is not None and str(w.code) != "preview":
        return str(w.code).replace("_", " "), w.reason
    return ("planned" if w.planned else "not planned"), w.reason


def _unsupported_row(u: UnsupportedSeam) -> dict[str, str]:
    row = dict.fromkeys(COLUMNS, "–")
    row.update(seam=u.id, status=SeamStatus.NOT_SUPPORTED.value, weld=f"not supported: {u.code}", detail=u.reason)
    return row


def _curve_row(w: SeamWeld) -> dict[str, str]:
    row = dict.fromkeys(COLUMNS, "–")
    weld = "welded" if w.welded else str(w.plan_code or w.code or "not welded").replace("_", " ")
    detail = f"TCP {w.quality.tcp_rms_mm:.2f} mm RMS from the true curve" if w.quality is not None else w.reason
    if w.partial:  # its arcs welded (planned), each stretch left for a manual weld in the detail
        weld = f"partial {w.share:.0%}, {w.manual_m * 1000.0:.0f} mm manual"
        left = "; ".join(f"manual weld {r.describe()}" for r in w.remainder)
        detail = f"{detail}; {left}" if w.quality is not None else w.reason
    row.update(seam=w.id, status=SeamStatus.FOUND.value, weld=weld, detail=detail)
    return row


def results_rows(
    records: Sequence[SeamRecord],
    unsupported: Sequence[UnsupportedSeam] = (),
    curves: Mapping[str, SeamWeld] | None = None,
) -> list[dict[str, str]]:
    """One dict per seam, then one per curved seam a weld run tried (``curves``: welded or why not), then one per
    seam the cell cannot weld (keys: :data:`COLUMNS` plus ``detail``, the reason in words)."""
    rows = []
    for rec in records:
        e, m, o = rec.estimate, rec.metrics, rec.outcome
        weld, detail = _weld(rec)
        err = "–" if m is None or not math.isfinite(m.paper_me_mm) else f"{m.paper_me_mm:.2f}"
        rows.append(
            {
                "seam": rec.id,
                "status": str(e.status),
                "sigma [mm]": _mm(e.sigma_m),
                "error [mm]": err,
                "weld": weld,
                "work angle [deg]": _deg(o.work_angle) if o is not None else "–",
                "travel angle [deg]": _deg(o.travel_angle) if o is not None else "–",
                "detail": detail or e.reason,
            }
        )
    return rows + [_curve_row(w) for w in (curves or {}).values()] + [_unsupported_row(u) for u in unsupported]


def results_table(
    records: Sequence[SeamRecord],
    status_colours: dict[str, str],
    unsupported: Sequence[UnsupportedSeam] = (),
    curves: Mapping[str, SeamWeld] | None = None,
) -> str:
    """The HTML ``<table id="results">``: one ``<tr data-seam=ID data-status=STATUS>`` per seam, the status cell
    in its colour, the reason in the row's tooltip."""
    head = "".join(f"<th>{html.escape(c)}</th>" for c in COLUMNS)
    body = []
    for row in results_rows(records, unsupported, curves):
        cells = []
        for c in COLUMNS:
            style = f' style="color:{status_colours[row[c]]};font-weight:bold"' if c == "status" else ""
            cells.append(f"<td{style}>{html.escape(row[c].replace('_', ' ') if c == 'status' else row[c])}</td>")
        tip = html.escape(row["detail"], quote=True)
        body.append(
            f'<tr data-seam="{html.escape(row["seam"], quote=True)}" data-status="{row["status"]}" title="{tip}">'
            + "".join(cells)
            + "</tr>"
        )
    return f'<table id="results"><thead><tr>{head}</tr></thead><tbody>{"".join(body)}</tbody></table>'
