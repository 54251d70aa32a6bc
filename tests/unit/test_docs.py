"""The generated docs are what their sources give now: docs/scenarios.md from the scenario models, the result
tables of docs/results.md and the README's headline table from benchmarks/results/. A model or a result changed
without regenerating fails here. The README stays a front page with the two commands CI and a new machine run."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path
from types import ModuleType

import pytest
from tools_loader import load_tool

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def scenario_docs() -> ModuleType:
    return load_tool("scenario_docs")


@pytest.fixture(scope="module")
def readme_results() -> ModuleType:
    return load_tool("readme_results")


def test_scenarios_md_is_generated_from_the_models(scenario_docs: ModuleType) -> None:
    committed = (REPO / "docs" / "scenarios.md").read_text(encoding="utf-8")
    assert committed == scenario_docs.render(), (
        f"docs/scenarios.md is out of date with the models of cell.scenario: regenerate it with {scenario_docs.COMMAND}"
    )


def test_scenarios_md_lists_every_key(scenario_docs: ModuleType) -> None:
    from cell.scenario import Scenario

    keys = {row.key for row in scenario_docs.rows(Scenario)}
    assert {"seed", "cameras.<name>.noise.subpixel_px", "process.travel_speed_mm_s", "rescan.escalate_mm"} <= keys
    assert "base_dir" not in keys  # set by the loader, never in a file
    by_key = {row.key: row for row in scenario_docs.rows(Scenario)}
    assert by_key["process.travel_speed_mm_s"].unit == "mm/s"
    assert by_key["cameras.<name>.eye_m"].default == "required"


def test_scenario_docs_check_mode(scenario_docs: ModuleType, tmp_path: Path) -> None:
    stale = tmp_path / "scenarios.md"
    stale.write_text("old\n", encoding="utf-8")
    assert scenario_docs.main(["--check", "--out", str(stale)]) == 1
    assert scenario_docs.main(["--out", str(stale)]) == 0
    assert scenario_docs.main(["--check", "--out", str(stale)]) == 0


def test_result_tables_are_generated_from_the_results(readme_results: ModuleType) -> None:
    assert readme_results.main(["--check"]) == 0, (
        f"docs/results.md's or the README's result tables differ from benchmarks/results/: regenerate them with "
        f"{readme_results.COMMAND}"
    )


def _copies(tmp_path: Path) -> tuple[Path, Path, Path]:
    """Copies of the results folder, docs/results.md and the README to change without touching the repository."""
    results = tmp_path / "results"
    shutil.copytree(REPO / "benchmarks" / "results", results)
    doc, readme = tmp_path / "results.md", tmp_path / "README.md"
    shutil.copy(REPO / "docs" / "results.md", doc)
    shutil.copy(REPO / "README.md", readme)
    return results, doc, readme


def test_results_check_fails_on_a_changed_result(readme_results: ModuleType, tmp_path: Path) -> None:
    results, doc, readme = _copies(tmp_path)
    rows = json.loads((results / "scaling.json").read_text(encoding="utf-8"))
    rows[0]["align_s"] += 1.0
    (results / "scaling.json").write_text(json.dumps(rows), encoding="utf-8")
    args = ["--doc", str(doc), "--readme", str(readme), "--results", str(results)]
    assert readme_results.main(["--check", *args]) == 1
    assert readme_results.main(args) == 0
    assert readme_results.main(["--check", *args]) == 0
    assert readme.read_text(encoding="utf-8") == (REPO / "README.md").read_text(encoding="utf-8")  # not a headline


def test_the_headline_table_follows_the_weld_result(readme_results: ModuleType, tmp_path: Path) -> None:
    results, doc, readme = _copies(tmp_path)
    runs = json.loads((results / "weld.json").read_text(encoding="utf-8"))
    runs[0]["welded"] = 15
    (results / "weld.json").write_text(json.dumps(runs), encoding="utf-8")
    args = ["--doc", str(doc), "--readme", str(readme), "--results", str(results)]
    assert readme_results.main(["--check", *args]) == 1
    assert readme_results.main(args) == 0
    assert "| 15/16, " in readme.read_text(encoding="utf-8")


def test_a_missing_marker_is_an_error(readme_results: ModuleType, tmp_path: Path) -> None:
    results, doc, readme = _copies(tmp_path)
    readme.write_text("# no headline block\n", encoding="utf-8")
    assert readme_results.main(["--doc", str(doc), "--readme", str(readme), "--results", str(results)]) == 1


def test_the_readme_is_a_front_page_with_the_two_commands() -> None:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) < 260
    lines = text.splitlines()
    # The two commands on a fresh machine; CI (.ci/run) runs the second as it is written here.
    assert any(line.startswith("./scripts/weld fence1 ") for line in lines)
    assert any(line.startswith("./scripts/test ") for line in lines)
    assert "./scripts/test" in (REPO / ".ci" / "run").read_text(encoding="utf-8")
    linked = set(re.findall(r"\]\((docs/[\w.-]+\.(?:md|png))", text))
    missing = sorted(p for p in linked if not (REPO / p).exists())
    assert not missing, f"the README links to files the repository does not have: {missing}"


REFERENCE_SECTIONS = {
    1: "The paper's setup and results",
    2: "Depth sensor noise",
    3: "KUKA KR 5 arc",
    4: "Welding process figures",
    5: "KRL export",
    6: "DXF maps",
    7: "Checks before moving",
    8: "Fault cases",
    9: "Ruckig and Pinocchio facts",
}
CITED_DIRS = ("cell", "tests", "benchmarks", "tools", "robots")


def _reference_headings() -> dict[int, str]:
    text = (REPO / "docs" / "reference.md").read_text(encoding="utf-8")
    return {int(m.group(1)): m.group(2).strip() for m in re.finditer(r"^## (\d+)\. (.+)$", text, flags=re.M)}


def test_reference_keeps_its_section_numbers() -> None:
    # The code cites these numbers; a renumbered or renamed section would point old citations at the wrong facts.
    assert _reference_headings() == REFERENCE_SECTIONS


def test_every_citation_of_the_reference_names_a_section_it_has() -> None:
    cite = re.compile(r"docs/reference\.md\s+sections?\s+(\d+)(?:\s*(?:,|and)\s*(\d+))*")
    headings = _reference_headings()
    bad = []
    for root in CITED_DIRS:
        for path in sorted((REPO / root).rglob("*")):
            if path.suffix not in {".py", ".yaml", ".urdf", ".md"} or "__pycache__" in path.parts:
                continue
            for m in cite.finditer(path.read_text(encoding="utf-8")):
                numbers = [int(n) for n in re.findall(r"\d+", m.group(0))]
                bad += [f"{path.relative_to(REPO)}: section {n}" for n in numbers if n not in headings]
    assert not bad, f"citations of sections docs/reference.md does not have: {bad}"


def test_no_citation_of_the_design_notes_is_left() -> None:
    fix_citations = load_tool("fix_citations")
    assert fix_citations.main(["--check"]) == 0, "run .venv/bin/python tools/fix_citations.py"


def _named_path_exists(named: str) -> bool:
    """A path a doc names: a file or folder, a glob (``maps/*.dxf``) or a module's member (``cell/x/y.name``)."""
    path = named.rstrip("/")
    if (REPO / path).exists() or ("*" in path and any(REPO.glob(path))):
        return True
    module, _, member = path.rpartition(".")
    return bool(member) and (REPO / f"{module}.py").exists()


@pytest.mark.parametrize("doc", sorted(p.name for p in (REPO / "docs").glob("*.md")))
def test_paths_the_docs_name_exist(doc: str) -> None:
    # The layout moves; a doc that names a file or package the repository no longer has is out of date.
    text = (REPO / "docs" / doc).read_text(encoding="utf-8")
    named = set(re.findall(r"`((?:cell|tools|benchmarks|robots|scenarios|maps|tests|docs|scripts)/[^`\s]*)`", text))
    missing = sorted(p for p in named if not _named_path_exists(p))
    assert not missing, f"docs/{doc} names paths that do not exist (update the doc): {missing}"
