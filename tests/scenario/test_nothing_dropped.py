"""A seam the cell cannot weld (a curve on the seam layer) is never dropped in silence: ``cell map info``, ``cell
scenario check``, the report, the summary line, the page, the robot program's header and the exit code all name it.
The part is the real scans' tee (two square tubes, two straight fillets) with a red circle drawn on its top."""

from __future__ import annotations

import json
from pathlib import Path

from dxf_factory import make_maps
from typer.testing import CliRunner

from cell.cli import app
from cell.errors import EXIT_PARTIAL


def _tee_with_a_circle(folder: Path) -> tuple[Path, str]:
    """The tee's map with a red CIRCLE on the horizontal tube's top; its path and the circle's seam id."""
    parts, junctions = make_maps.designs()["tee"]
    doc = make_maps.build_map(parts, make_maps.design_seams("tee", parts, junctions))
    circle = doc.modelspace().add_circle((100.0, 0.0, 25.4), 15.0, dxfattribs={"color": 1})
    path = folder / "tee.dxf"
    doc.saveas(path)
    return path, f"seam-{circle.dxf.handle}"


def test_a_curved_seam_is_named_by_every_output(tmp_path: Path) -> None:
    dxf, curve = _tee_with_a_circle(tmp_path)
    runner = CliRunner()

    def cell(*args: str) -> tuple[int, str, str]:
        r = runner.invoke(app, list(args))
        return r.exit_code, r.stdout, r.stderr

    code, out, err = cell("map", "info", str(dxf))
    assert code == 0 and "curved seams: 1 (a run locates each and welds it or says why not; 1 with no joint" in out, err
    assert any(
        line.split()[:1] == [curve] and "circle r 15.0 mm" in line and "[CIRCLE" in line for line in out.splitlines()
    )

    scenario = tmp_path / "tee.yaml"
    assert cell("init", str(dxf), "--out", str(scenario))[0] == 0
    code, out, err = cell("scenario", "check", str(scenario))
    assert code == 0 and "3 seams: 2 to weld, 1 not supported (curved_not_located)" in out, out + err
    assert f"seam {curve} will not be welded: not supported (curved_not_located)" in " ".join(err.split())

    report, program, page = tmp_path / "r.json", tmp_path / "program", tmp_path / "page.html"
    code, out, err = cell(
        "weld", str(scenario), "--sides", "first", "--json", str(report), "--program", str(program), "--html", str(page)
    )
    # Both straight fillets are welded: the curve alone makes the run partial, and the last line says so.
    assert code == EXIT_PARTIAL, err
    assert err.strip().splitlines()[-1] == "exit 3: 1 seam not supported (curved_not_located: 1); 2/2 welded"
    assert "welded 2 of 3 seams in the map; 1 not supported: curved_not_located" in out
    assert f"  {curve}: CIRCLE" in out  # the table's row and its reason in words
    assert any(line.split()[:2] == [curve, "-"] and "not_supported" in line for line in out.splitlines())

    rep = json.loads(report.read_text())
    [entry] = [s for s in rep["seams"] if s["id"] == curve]
    assert (entry["status"], entry["reason_code"]) == ("not_supported", "curved_not_located")
    assert (entry["welded"], entry["weld_reason_code"], entry["side"]) == (False, "not_supported", None)
    assert rep["summary"]["seams"] == 3 and rep["summary"]["not_supported"] == {"curved_not_located": 1}
    assert rep["welded"] == 2 and rep["summary"]["visible"] == 2

    html = page.read_text()
    assert f'data-seam="{curve}" data-status="not_supported"' in html and "1 not supported: curved_not_located" in html

    [src] = program.glob("*.src")
    head = src.read_text().split("PTP XHOME")[0]
    assert f";-   {curve}: not_supported: curved_not_located" in head and "Not welded by this job: 1 seam(s)" in head
