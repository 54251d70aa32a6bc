"""What made an output: the provenance record (version, commit, time, command, seed, hashes) and its KRL lines."""

from __future__ import annotations

import datetime as dt
import hashlib
import re
from pathlib import Path

from cell import scenario as sc
from cell.provenance import header_lines, provenance, version, version_text


def test_the_record_names_code_inputs_and_command() -> None:
    scn = sc.load("fence1")
    path = sc.resolve("fence1")
    when = dt.datetime(2026, 3, 4, 5, 6, 7, 890, tzinfo=dt.UTC)
    rec = provenance(scn, scenario_file=path, argv=["/x/bin/cell", "weld", "fence1", "--json", "a b.json"], now=when)
    assert rec["version"] == version() != ""
    assert re.fullmatch(r"[0-9a-f]{40}(\+dirty)?|unknown", rec["commit"])
    assert rec["timestamp_utc"] == "2026-03-04T05:06:07Z"
    assert rec["command"] == "cell weld fence1 --json 'a b.json'"
    assert rec["seed"] == scn.seed
    assert rec["scenario_sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    assert rec["map_sha256"] == hashlib.sha256(Path(rec["map_file"]).read_bytes()).hexdigest()
    assert Path(rec["map_file"]) == scn.map_path


def test_without_a_scenario_or_its_file_the_fields_are_null() -> None:
    rec = provenance(None, argv=["cell", "bench"])
    assert rec["seed"] is None and rec["scenario_sha256"] is None and rec["map_sha256"] is None
    assert version_text().startswith(f"cell {rec['version']}")


def test_krl_header_lines_are_ascii_comments() -> None:
    rec = provenance(sc.load("fence1"), scenario_file=sc.resolve("fence1"), argv=["cell", "weld", "fänce"])
    lines = header_lines(rec)
    assert all(ln.startswith(";- ") and ln.isascii() for ln in lines)
    assert rec["commit"] in lines[0] and rec["timestamp_utc"] in lines[0]
    assert any(rec["scenario_sha256"] in ln for ln in lines) and any(rec["map_sha256"] in ln for ln in lines)
    assert any(ln == f";- seed: {rec['seed']}" for ln in lines)
