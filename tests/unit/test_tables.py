"""The summary line under a weld or preview table counts every seam of the map: welded (or, in a dry run, planned)
of all of them, and the ones the cell cannot weld by reason code."""

from __future__ import annotations

from typing import Any

from cell.cli.printout.tables import not_supported_text, weld_summary


def _report(codes: list[str | None], welded: list[bool], unsupported: dict[str, int]) -> dict[str, Any]:
    seams = [
        {"id": f"S{i}", "welded": w, "planned": w or c == "preview", "weld_reason_code": c}
        for i, (c, w) in enumerate(zip(codes, welded, strict=True))
    ]
    n = len(seams) + sum(unsupported.values())
    seams += [
        {"id": f"C{i}", "welded": False, "planned": False, "weld_reason_code": "not_supported"}
        for i in range(n - len(seams))
    ]
    return {
        "seams": seams,
        "welded": sum(welded),
        "cycle_time_s": 12.0 if any(welded) else None,
        "planned_cycle_time_s": 12.0,
        "summary": {"seams": n, "not_supported": unsupported, "visible": 3, "found": 3, "paper_me_mean_mm": 0.1},
    }


def test_a_weld_counts_every_seam_of_the_map_and_names_the_unsupported() -> None:
    rep = _report([None, None, "end_uncertain"], [True, True, False], {"curved": 1})
    line = weld_summary(rep)
    assert line.startswith("welded 2 of 4 seams in the map; 1 not supported: curved · visible 3 · located 3")
    assert not_supported_text({"not_supported": {"curved": 2, "on_fixture": 1}}) == (
        "3 not supported: curved (2), on_fixture"
    )
    assert not_supported_text({"not_supported": {"curved_not_located": 1, "curved_no_torch_path": 2}}) == (
        "1 not supported: curved_not_located; 2 curved located, not welded (curved_no_torch_path)"
    )
    assert weld_summary(_report([None], [True], {})).startswith("welded 1 of 1 seams in the map · visible")


def test_a_dry_run_counts_what_it_planned() -> None:
    rep = _report(["preview", "preview", "not_planned"], [False, False, False], {"curved": 1})
    assert weld_summary(rep).startswith("planned 2 of 4 seams in the map; 1 not supported: curved")
    assert weld_summary(rep).endswith("cycle time 12.0 s (planned)")
