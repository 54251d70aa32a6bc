"""The re-scan's tables (``cell rescan``): each straight seam's errors before and after its close-up, one line per
curved seam (its sigmas, close-ups and errors before and after), and the summary line."""

from __future__ import annotations

from cell.cli.common import out
from cell.cli.printout.tables import compact_table, num, why_lines

RESCAN_LEGEND = "lat, end: lateral and endpoint error [mm], before (0) and after the close-up"


def print_rescan(rep: dict) -> None:
    t = compact_table(
        f"re-scan {rep['scenario']} · method {rep['method']} · frame R",
        ("seam", "lat 0", "lat", "end 0", "end", "weight", "why not"),
    )
    whys = []
    for s in (s for s in rep["seams"] if not s.get("curved")):
        b, a = s.get("error_mm_before", {}), s.get("error_mm", {})
        r = s["rescan"]
        t.add_row(
            s["id"],
            num(b.get("lateral")),
            num(a.get("lateral")),
            num(b.get("endpoint")),
            num(a.get("endpoint")),
            num(r["weight"]),
            "" if r["used"] else "not used",
        )
        whys.append((s["id"], r["reason"]))
    out.print(t)
    out.print(RESCAN_LEGEND, soft_wrap=True, markup=False)
    why_lines(whys)
    _curve_rescans(rep)
    b, a, c = rep["summary_before_rescan"], rep["summary"], rep["rescan"].get("curves") or {}
    out.print(
        f"{rep['rescan']['seams']} seams re-scanned ({rep['rescan']['used']} used) · mean lateral"
        f" {num(b['lateral_mean_mm'], 3)} -> {num(a['lateral_mean_mm'], 3)} mm · mean endpoint"
        f" {num(b['endpoint_mean_mm'], 3)} -> {num(a['endpoint_mean_mm'], 3)} mm · robot time"
        f" {num(rep['rescan']['motion_s'], 1)} s"
        + (f" · {c['seams']} curves re-scanned, {c['within_tolerance']} now within the tolerance" if c else ""),
        soft_wrap=True,
    )


def _curve_rescans(rep: dict) -> None:
    """One line per curved seam of a ``cell rescan`` report: its worst sigma and its ends' (or closed) before and
    after, the close-ups taken and their robot time, its error before and after (simulation); then why it was not
    re-scanned or is still over the tolerance."""
    for s in (s for s in rep["seams"] if s.get("curved")):
        r, c = s["rescan"], s.get("curve")
        line = f"curve {s['id']}: "
        if not r["chosen"]:
            out.print(line + r["reason"], soft_wrap=True, markup=False, highlight=False)
            continue
        after = c["sigma_max_mm"] if c is not None else None
        line += f"sigma max {num(r['sigma_max_mm_before'], 3)} -> {num(after, 3)} mm"
        if c is not None and c["end_sigma_mm"] is not None:
            ends = r["end_sigma_mm_before"] or [None, None]
            line += ", ends +-" + "/".join(map(num, ends)) + " -> " + "/".join(map(num, c["end_sigma_mm"])) + " mm"
        elif c is not None:
            line += ", closed"
        line += f" ({'within' if r['within_tolerance'] else 'over'} the tolerance); {r['views']} close-ups"
        line += f", {num(r['motion_s'], 1)} s, weight {num(r['weight'])}"
        if any(r.get("e1_mm") or ()):  # a linear track's carriage moved for them
            line += ", from E1 = " + "/".join(num(e, 0) for e in r["e1_mm"]) + " mm"
        b, a = s.get("error_mm_before"), s.get("error_mm")
        if b is not None or a is not None:
            b, a = b or {}, a or {}
            line += f"; error rms {num(b.get('rms'))} -> {num(a.get('rms'))} mm"
        out.print(line, soft_wrap=True, markup=False, highlight=False)
        why_lines([(s["id"], r["reason"])])
