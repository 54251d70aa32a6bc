"""A whole sweep: the folder opened (resume), the runs not yet there sent to the engine, each finished run kept
at once, the summary and pictures rewritten at intervals and at the end (also when interrupted)."""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cell.outputs import write_text
from cell.scenario import Scenario
from cell.sweep.store import RunStore, open_store, sweep_params
from cell.sweep.summary import summarize
from cell.sweep.task import Stage
from cell.sweep.variations import variation
from cell.types import WeldMap

SUMMARY = "summary.json"
SUMMARY_EVERY_S = 10.0  # [s] summary.json rewritten at least this often while runs finish
PICTURES_EVERY_S = 120.0  # [s] the pictures (about a second of drawing each time)


@dataclass(frozen=True)
class SweepSpec:
    """What to sweep: the scenario and its map (frame M), N, what varies, to which stage, with which locator."""

    scenario: Scenario
    weldmap_M: WeldMap
    n: int
    vary: tuple[str, ...]
    stage: Stage
    method: str | None = None
    map_sha256: str | None = None
    scenario_sha256: str | None = None  # the scenario file's (None: of its values)


@dataclass
class Study:
    """One sweep into one folder. ``count(done, n)`` is told every finished run; ``say`` and ``warn`` lines."""

    spec: SweepSpec
    out: Path
    count: Callable[[int, int], None]
    say: Callable[[str], None]
    warn: Callable[[str], None]
    address: str | None = None
    workers: int | None = None
    engine: dict[str, Any] | None = None
    store: RunStore | None = None
    code: str = ""  # the commit the sweep was started from (``+dirty``: with edits)
    _summary_t: float = 0.0
    _pictures_t: float = 0.0

    def run(self, *, fresh: bool = False) -> dict[str, Any]:
        """Run what is missing of runs 0 .. n-1 and return the summary (written to ``summary.json``)."""
        from cell.provenance import git_commit
        from cell.sweep.engine import EngineInfo, engine_version, run_sweep

        s = self.spec
        params = sweep_params(s.scenario, s.map_sha256, s.vary, s.stage, s.method, s.scenario_sha256)
        self.store = store = open_store(self.out, params, fresh=fresh, warn=self.warn)
        todo = [variation(s.scenario, s.weldmap_M, k, s.vary) for k in range(s.n) if k not in store.lines]
        done = sum(1 for k in store.lines if k < s.n)
        self.code = git_commit()  # the driver's checkout: the workers' numbers come from the code they import
        self.engine = {"engine": "ray", "engine_version": engine_version(), "address": self.address or "local"}
        if done:
            self.say(f"resuming {self.out}: {done} of {s.n} runs already there, {len(todo)} to run")
        self.count(done, s.n)

        def started(info: EngineInfo) -> None:
            self.engine = {"engine": info.engine, "engine_version": info.engine_version, "address": info.address}
            self.engine["cpus"] = info.cpus
            self.say(f"Ray {info.engine_version} ({info.address}, {info.cpus} CPUs): {len(todo)} runs")

        def finished(result: dict[str, Any]) -> None:
            store.append(result)
            self.count(sum(1 for k in store.lines if k < s.n), s.n)
            now = time.monotonic()
            if now - self._summary_t >= SUMMARY_EVERY_S:
                self.write_summary(pictures=now - self._pictures_t >= PICTURES_EVERY_S)

        self._summary_t = self._pictures_t = time.monotonic()
        try:
            if todo:
                run_sweep(
                    s.scenario,
                    todo,
                    s.stage,
                    finished,
                    method=s.method,
                    address=self.address,
                    workers=self.workers,
                    on_start=started,
                )
        finally:
            store.close()
            summary = self.write_summary(pictures=True)
        return summary

    def summary(self) -> dict[str, Any]:
        """The summary of the runs kept so far."""
        s, store = self.spec, self.store
        assert store is not None, "run() opens the store"
        return summarize(
            store.lines.values(),
            [m.id for m in s.weldmap_M.seams],
            n=s.n,
            stage=s.stage,
            engine={**(self.engine or {}), "code": self.code},
            sweep={**store.params, "key": store.key},
            weld_tolerance_mm=s.scenario.rescan.weld_tolerance_mm,
        )

    def write_summary(self, *, pictures: bool) -> dict[str, Any]:
        """Rewrite ``summary.json`` (whole: written aside, then moved over) and, if asked, the pictures."""
        summary = self.summary()
        path = self.out / SUMMARY
        write_text(path, json.dumps(summary, indent=2) + "\n", what="sweep summary")  # seams in map order
        self._summary_t = time.monotonic()
        if pictures and self.store is not None:
            from cell.sweep.pictures import write_pictures

            lines = [ln for k, ln in self.store.lines.items() if k < self.spec.n]
            write_pictures(self.out, self.spec.weldmap_M, summary, lines)
            self._pictures_t = time.monotonic()
        return summary
