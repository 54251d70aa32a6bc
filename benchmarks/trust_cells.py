"""One cell of the trust benchmark: made from its seed, run headless to its stage, reduced to its stored line.

A cell is a random cell of ``tools/random_cells.py`` (``make_cell(seed, out_dir, kind)``: map, scenario and truth
written to ``out_dir``), or, with ``scenarios``, a public scenario run with the cell's seed (new sensor noise and, where
the scenario has them, new as-built deviations and calibration errors). ``detect`` runs what ``cell detect --json`` runs
(:func:`cell.pipeline.detect`, :func:`cell.export.reports.report.detection_report`); ``weld`` what
``cell weld --sides first --json`` runs (:func:`cell.pipeline.weld`, :func:`cell.export.reports.report.weld_report`):
the part as it lies.
Every figure is read from that report (:mod:`trust_metrics`). A cell never raises: a failure is its line's
``error``.
"""

from __future__ import annotations

import hashlib
import json
import signal
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import trust_metrics as tm

REPO = Path(__file__).resolve().parent.parent
TOOLS = REPO / "tools"


@dataclass(frozen=True)
class CellJob:
    """What one worker runs: cell index ``k`` of the benchmark, its seed, the stage, where its files go, and the
    public scenario it stands for (None: a random cell of ``kind``)."""

    k: int
    cell_seed: int
    stage: str
    kind: str
    out_dir: Path
    scenario: str | None = None
    method: str | None = None


def cell_seed(seed: int, k: int) -> int:
    """Cell ``k``'s own seed, drawn from the benchmark's ``seed`` and ``k`` alone (cell k is the same cell
    whatever the number of cells): a 32-bit integer."""
    return int(np.random.SeedSequence([seed, k]).generate_state(1)[0])


def ignore_interrupt() -> None:
    """A pool worker's start: Ctrl-C is the driver's to handle (it stops the workers), never a worker's."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def generator() -> Any:
    """The random-cell generator, ``tools/random_cells.py`` as a module."""
    if str(TOOLS) not in sys.path:
        sys.path.insert(0, str(TOOLS))
    import random_cells

    return random_cells


def generator_sha256() -> str:
    """One digest of the generator's files (``tools/random_cell*.py``): another digest, other cells."""
    h = hashlib.sha256()
    for path in sorted(TOOLS.glob("random_cell*.py")):
        h.update(path.name.encode() + b"\0" + path.read_bytes())
    return h.hexdigest()


def _scenario(job: CellJob) -> tuple[Any, str]:
    """The scenario of ``job`` (a :class:`cell.scenario.Scenario`) and how the results name it."""
    from cell import scenario as sc

    if job.scenario is not None:
        s = sc.load(job.scenario)
        return s.model_copy(update={"seed": job.cell_seed}), job.scenario
    cell = generator().make_cell(job.cell_seed, job.out_dir, kind=job.kind)
    path = Path(cell.scenario).resolve()
    return sc.load(path), str(path.relative_to(REPO)) if path.is_relative_to(REPO) else str(path)


def report_of(job: CellJob, scenario: Any) -> dict[str, Any]:
    """Run ``scenario`` to ``job.stage`` and return the report the CLI's ``--json`` writes (a CellError that
    stops the run before any report propagates)."""
    from cell import pipeline
    from cell.export.reports.report import detection_report, weld_report

    if job.stage == "detect":
        return detection_report(pipeline.detect(scenario, job.method))
    return weld_report(pipeline.weld(scenario, pipeline.WeldJob(job.method)))


def run_cell(job: CellJob) -> dict[str, Any]:
    """Make and run one cell; ``{"line": ..., "timings": ...}`` as :class:`cell.sweep.store.RunStore` keeps it.
    The line: ``run`` (= ``cell``), the cell's seed and scenario, :func:`trust_metrics.cell_record` of its report,
    ``error`` (None, or the type, message and exit code of what stopped it before a report), ``make_s`` and
    ``wall_s``. The report itself is written to the cell's folder (``report-<stage>.json``)."""
    from cell.export.reports.report import write_json
    from cell.provenance import git_commit
    from cell.sweep.task import error_json

    t0 = time.perf_counter()
    line: dict[str, Any] = {
        "run": job.k,
        "cell": job.k,
        "cell_seed": job.cell_seed,
        "kind": job.kind if job.scenario is None else "public",
        "scenario": job.scenario,
        "commit": git_commit(),
        "error": None,
    }
    make_s = 0.0
    try:
        job.out_dir.mkdir(parents=True, exist_ok=True)
        scenario, name = _scenario(job)
        line["scenario"] = name
        make_s = time.perf_counter() - t0
        rep = report_of(job, scenario)
        write_json(job.out_dir / f"report-{job.stage}.json", rep)
        line.update(tm.cell_record(json.loads(json.dumps(rep)), job.stage))
    except Exception as e:
        line["error"] = {**error_json(e), "traceback": traceback.format_exc(limit=6)}
    wall_s = time.perf_counter() - t0
    line["make_s"], line["wall_s"] = round(make_s, 2), round(wall_s, 2)
    return {"line": line, "timings": {"make_s": round(make_s, 3), "wall_s": round(wall_s, 3)}}
