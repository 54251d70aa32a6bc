"""A sweep's output folder: what the sweep is (``sweep.json``), one line per finished run (``runs.jsonl``) and the
runs' timings apart; resumed by the same sweep, refused to another unless ``fresh``, a torn last line dropped
(docs/sweep.md, "The output folder")."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from cell.errors import UsageError
from cell.outputs import write_text
from cell.scenario import Scenario

MANIFEST = "sweep.json"
RUNS = "runs.jsonl"
TIMINGS = "timings.jsonl"
FORMAT = 1


def dumps(obj: Any) -> str:
    """The one JSON spelling of a line: sorted keys, no spaces (the same bytes for the same values)."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False)


def sweep_params(
    scenario: Scenario,
    map_sha256: str | None,
    vary: tuple[str, ...],
    stage: str,
    method: str | None,
    scenario_sha256: str | None = None,
) -> dict[str, Any]:
    """What makes two sweeps the same sweep (N aside: run k is the same run whatever N is). scenario_sha256 :
    the scenario file's digest (default: of the loaded scenario's values, which a new default key changes)."""
    if scenario_sha256 is None:
        scenario_sha256 = hashlib.sha256(dumps(scenario.model_dump(mode="json")).encode()).hexdigest()
    return {
        "format": FORMAT,
        "scenario": scenario.name,
        "scenario_sha256": scenario_sha256,
        "map_sha256": map_sha256,
        "seed": scenario.seed,
        "vary": list(vary),
        "stage": stage,
        "method": method or scenario.locator.method,
    }


def params_key(params: Mapping[str, Any]) -> str:
    """A short digest of the parameters, carried by every line (a line from another sweep is recognised)."""
    return hashlib.sha256(dumps(dict(params)).encode()).hexdigest()[:16]


@dataclass
class RunStore:
    """The output folder of one sweep: finished lines by run index, and the appenders for new ones."""

    out: Path
    params: dict[str, Any]
    lines: dict[int, dict[str, Any]] = field(default_factory=dict)
    dropped: list[str] = field(default_factory=list)  # what was dropped on reading, one line each
    _runs: IO[str] | None = None
    _timings: IO[str] | None = None

    @property
    def key(self) -> str:
        return params_key(self.params)

    def append(self, result: Mapping[str, Any]) -> dict[str, Any]:
        """Keep one finished run: its line appended to runs.jsonl and flushed, its timings to timings.jsonl."""
        line = {**result["line"], "key": self.key}
        if self._runs is None:
            self._runs = (self.out / RUNS).open("a", encoding="utf-8")
            self._timings = (self.out / TIMINGS).open("a", encoding="utf-8")
        self._runs.write(dumps(line) + "\n")
        self._runs.flush()
        if self._timings is not None:
            self._timings.write(dumps({"run": line["run"], **dict(result.get("timings", {}))}) + "\n")
            self._timings.flush()
        self.lines[int(line["run"])] = line
        return line

    def close(self) -> None:
        for f in (self._runs, self._timings):
            if f is not None:
                f.close()
        self._runs = self._timings = None


def open_store(out: Path, params: dict[str, Any], *, fresh: bool, warn: Callable[[str], None]) -> RunStore:
    """The folder ``out`` for the sweep ``params``: created if new; its finished runs read (resume); emptied of
    a previous sweep's files when ``fresh``. UsageError when it holds a different sweep (and not ``fresh``)."""
    out.mkdir(parents=True, exist_ok=True)
    manifest = out / MANIFEST
    if fresh:
        for name in (MANIFEST, RUNS, TIMINGS):
            (out / name).unlink(missing_ok=True)
    if manifest.exists():
        try:
            old = json.loads(manifest.read_text(encoding="utf-8"))
        except (OSError, ValueError) as e:
            raise UsageError(
                f"--out {str(out)!r}: {MANIFEST} cannot be read ({e}); use --fresh to start over"
            ) from None
        if old != params:
            diff = sorted(k for k in set(old) | set(params) if old.get(k) != params.get(k))
            raise UsageError(
                f"--out {str(out)!r} holds a different sweep ({', '.join(diff)} differ); give another --out, or"
                " --fresh to replace it"
            )
    elif (out / RUNS).exists():
        raise UsageError(f"--out {str(out)!r} has {RUNS} but no {MANIFEST}; give another --out, or --fresh")
    write_text(manifest, json.dumps(params, indent=2, sort_keys=True) + "\n", what="sweep manifest")
    store = RunStore(out, params)
    _read_runs(store, warn)
    return store


def _read_runs(store: RunStore, warn: Callable[[str], None]) -> None:
    """Read runs.jsonl into ``store.lines``; torn or foreign lines dropped with a warning, the file rewritten
    without them (so appends start on a fresh line)."""
    path = store.out / RUNS
    if not path.exists():
        return
    raw = path.read_text(encoding="utf-8", errors="replace")
    kept: list[str] = []
    rows = raw.split("\n")
    if rows and rows[-1] == "":
        rows.pop()
    for i, text in enumerate(rows, start=1):
        try:
            line = json.loads(text)
            k = int(line["run"])
        except (ValueError, KeyError, TypeError):
            where = "the last line" if i == len(rows) else f"line {i}"
            store.dropped.append(f"{RUNS}: {where} is not a whole run (cut off by a kill?): dropped, run again")
            continue
        if line.get("key") != store.key:
            store.dropped.append(f"{RUNS}: line {i} (run {k}) belongs to another sweep: dropped")
            continue
        if k in store.lines:
            continue  # the same run twice (a resumed sweep that raced a kill): the first is kept
        store.lines[k] = line
        kept.append(text)
    for msg in store.dropped:
        warn(msg)
    if store.dropped or (raw and not raw.endswith("\n")):
        write_text(path, "".join(t + "\n" for t in kept), what="sweep runs")
