"""The trust benchmark: the real pipeline, headless, on random cells nobody tuned for; does the cell's confidence
hold (docs/trust.md, "The trust benchmark")?

    .venv/bin/python benchmarks/bench_trust.py --cells N --seed S --stage detect|weld [--workers K] [--out PATH]
        [--fresh] [--retry-failed] [--store DIR] [--kind random] [--scenarios fence1,brace,...] [--method NAME]

Cell k is made by ``tools/random_cells.py`` from its own seed (:func:`trust_cells.cell_seed` of S and k), or, with
``--scenarios``, is the k-th of those public scenarios in turn, run with that seed. ``detect`` runs what ``cell
detect --json`` runs on it, ``weld`` what ``cell weld --sides first --json`` runs, and every figure is read from
that report (:mod:`trust_metrics`). Cells run on a pool of K processes (default 2); each finished cell is stored
at once (``--store``, default ``runs/trust/<stage>-seed<S>-<key>/``, one line per cell: :mod:`cell.sweep.store`),
so a rerun runs only the cells not yet done (``--fresh``: all again; ``--retry-failed``: also those that failed).
The figures over the cells 0 .. N-1 go to ``--out`` (default ``benchmarks/results/trust.json``) as the block of
the stage, beside the other stage's block; ``tools/readme_results.py`` renders docs/results.md's table from it.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import shlex
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from pathlib import Path
from typing import Any

BENCH = Path(__file__).resolve().parent
if str(BENCH) not in sys.path:  # its sibling modules, also when loaded by path (the tests)
    sys.path.insert(0, str(BENCH))

import trust_cells as tc  # noqa: E402  (after the path set-up above)
import trust_metrics as tm  # noqa: E402

from cell.errors import UsageError  # noqa: E402
from cell.export.reports.report import write_json  # noqa: E402
from cell.provenance import git_commit  # noqa: E402
from cell.sweep.store import RUNS, RunStore, dumps, open_store, params_key  # noqa: E402

RESULTS = BENCH / "results"
STORE = tc.REPO / "runs" / "trust"  # git ignores runs/
STAGES = ("detect", "weld")
FORMAT = 1

Result = dict[str, Any]


def _say(msg: str) -> None:
    print(f"· {msg}", file=sys.stderr, flush=True)


def store_params(stage: str, seed: int, kind: str, scenarios: Sequence[str], method: str | None) -> dict[str, Any]:
    """What makes two runs of the benchmark run the same cells (N aside: cell k is the same whatever N is): the
    stage, seed, kind, stand-in scenarios, method and the generator's digest (a changed generator makes other
    cells)."""
    return {
        "format": FORMAT,
        "bench": "trust",
        "stage": stage,
        "seed": seed,
        "kind": kind,
        "scenarios": list(scenarios),
        "method": method,
        "generator_sha256": None if scenarios else tc.generator_sha256(),
    }


def open_cells(store_dir: Path | None, params: dict[str, Any], fresh: bool) -> RunStore:
    """The store of the cells' lines: ``store_dir``, or a folder of its own for these parameters under runs/."""
    out = store_dir or STORE / f"{params['stage']}-seed{params['seed']}-{params_key(params)[:8]}"
    try:
        return open_store(out, params, fresh=fresh, warn=_say)
    except UsageError as e:
        raise UsageError(e.message.replace("--out", "--store")) from None


def drop_failed(store: RunStore) -> list[int]:
    """Forget the stored cells that failed (their lines cut from the store's file), so they run again."""
    failed = sorted(k for k, ln in store.lines.items() if ln.get("error") is not None)
    for k in failed:
        del store.lines[k]
    if failed:
        (store.out / RUNS).write_text("".join(dumps(ln) + "\n" for ln in store.lines.values()), encoding="utf-8")
    return failed


@contextmanager
def _pool(workers: int) -> Iterator[ProcessPoolExecutor]:
    """A pool of ``workers`` fresh processes. Its workers ignore Ctrl-C: the driver takes it and stops them at once
    (their cells are lost, and run by the next run); on a normal exit it waits for them."""
    pool = ProcessPoolExecutor(workers, mp_context=mp.get_context("spawn"), initializer=tc.ignore_interrupt)
    try:
        yield pool
    except BaseException:
        for proc in list((pool._processes or {}).values()):  # no public way to stop them before Python 3.14
            proc.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def _alone(job: tc.CellJob) -> Result:
    """Run one cell in a process of its own; a cell that kills its process is a failed cell."""
    with _pool(1) as pool:
        try:
            return pool.submit(tc.run_cell, job).result()
        except BrokenProcessPool:
            err = {"type": "WorkerDied", "message": "the cell's process died", "exit_code": 1}
            line = {"run": job.k, "cell": job.k, "cell_seed": job.cell_seed, "scenario": job.scenario, "error": err}
            return {"line": line, "timings": {}}


def run_cells(jobs: Sequence[tc.CellJob], workers: int, on_result: Callable[[Result], None]) -> None:
    """Run ``jobs``, ``workers`` at a time (in this process when 1), calling ``on_result`` as each finishes. At
    most ``workers`` cells are in flight; when a process dies, those cells are run again one by one, each alone,
    so only the one that kills its process is recorded as failed."""
    if workers <= 1:
        for job in jobs:
            on_result(tc.run_cell(job))
        return
    os.environ.setdefault("OMP_NUM_THREADS", "1")  # each worker one OpenMP thread (as a sweep's Ray task)
    queue = list(jobs)
    while queue:
        suspects: list[tc.CellJob] = []
        with _pool(workers) as pool:
            pending: dict[Any, tc.CellJob] = {}
            try:
                while queue or pending:
                    while queue and len(pending) < workers:
                        job = queue.pop(0)
                        pending[pool.submit(tc.run_cell, job)] = job
                    done, _ = wait(pending, return_when=FIRST_COMPLETED)
                    for f in done:
                        job = pending.pop(f)
                        try:
                            result = f.result()
                        except BrokenProcessPool:
                            suspects.append(job)
                            continue
                        on_result(result)
            except BrokenProcessPool:
                pass
            suspects.extend(pending.values())
        for job in suspects:
            on_result(_alone(job))


def results_block(argv: Sequence[str], args: argparse.Namespace, store: RunStore, wall_s: float, ran: int) -> Result:
    """The stage's block of trust.json: how it was made (command, seed, commit, wall time) and
    :func:`trust_metrics.block` of the cells 0 .. N-1."""
    lines = [store.lines[k] for k in range(args.cells) if k in store.lines]
    return {
        "stage": args.stage,
        "command": shlex.join([".venv/bin/python", "benchmarks/bench_trust.py", *argv]),
        "seed": args.seed,
        "kind": "public" if args.scenarios else args.kind,
        "scenarios": args.scenarios or None,
        "method": args.method,
        "workers": args.workers,
        "commit": git_commit(),
        "cell_commits": sorted({ln.get("commit", "unknown") for ln in lines}),
        "generator_sha256": store.params["generator_sha256"],
        "wall_s": round(wall_s, 1),
        "cells_run_now": ran,
        **tm.block(lines, args.stage),
    }


def write_results(path: Path, stage: str, blk: Result) -> Path:
    """Put ``blk`` as ``stage``'s block of the results file at ``path``, keeping the other stage's block."""
    import json

    data: dict[str, Any] = {}
    if path.exists():
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
            data = old if isinstance(old, dict) else {}
        except ValueError:
            _say(f"{path}: not JSON, replaced")
    data[stage] = blk
    return write_json(path, {k: data[k] for k in STAGES if k in data})


def brief(blk: Result) -> str:
    """A few lines for the terminal."""
    keys = ["cells", "cells_failed", "seams_visible", "located_share", "coverage_2sigma_across"]
    keys += ["coverage_2sigma_ends", "splice_corrections_exact", "welded_share", "worst_welded_tcp_max_mm"]
    keys += ["beads_past_end"]
    out = " ".join(f"{k}={blk[k]}" for k in keys if k in blk)
    w = blk["cell_wall_s"]
    return f"{out}\nper cell: median {w['median']} s, max {w['max']} s; this sitting {blk['wall_s']} s"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cells", type=int, required=True, help="cells 0 .. N-1")
    ap.add_argument("--seed", type=int, default=0, help="the benchmark's seed (each cell's own seed comes from it)")
    ap.add_argument("--stage", choices=STAGES, required=True)
    ap.add_argument("--workers", type=int, default=2, help="cells run at once, one process each")
    ap.add_argument("--out", type=Path, default=RESULTS / "trust.json", help="the results file")
    ap.add_argument("--fresh", action="store_true", help="run every cell again (the store emptied)")
    ap.add_argument("--retry-failed", action="store_true", help="run the stored cells that failed again")
    ap.add_argument("--store", type=Path, default=None, help="the folder of the cells' lines and files")
    ap.add_argument("--kind", default="random", help="the generator's kind of cell")
    ap.add_argument("--scenarios", default="", help="comma-separated public scenarios instead of random cells")
    ap.add_argument("--method", default=None, help="the locator (default: each scenario's)")
    args = ap.parse_args(argv)
    args.scenarios = [s.strip() for s in args.scenarios.split(",") if s.strip()]
    if args.cells < 1 or args.workers < 1:
        ap.error("--cells and --workers must be at least 1")
    try:
        params = store_params(args.stage, args.seed, args.kind, args.scenarios, args.method)
        store = open_cells(args.store, params, args.fresh)
    except UsageError as e:
        print(f"error: {e.message}", file=sys.stderr)
        return e.exit_code
    if args.retry_failed and (again := drop_failed(store)):
        _say(f"cells {', '.join(map(str, again))} failed before: run again")
    todo = [k for k in range(args.cells) if k not in store.lines]
    _say(f"{store.out}: {args.cells - len(todo)} of {args.cells} cells done, {len(todo)} to run")
    jobs = [
        tc.CellJob(
            k,
            tc.cell_seed(args.seed, k),
            args.stage,
            args.kind,
            store.out / "cells" / str(k),
            args.scenarios[k % len(args.scenarios)] if args.scenarios else None,
            args.method,
        )
        for k in todo
    ]

    def on_result(result: Result) -> None:
        line = store.append(result)
        what = line["error"]["type"] if line.get("error") else f"{len(line.get('seams', []))} seams"
        _say(f"cell {line['run']} ({line.get('scenario')}): {what}, {line.get('wall_s')} s")

    t = time.perf_counter()
    try:
        run_cells(jobs, args.workers, on_result)
    except KeyboardInterrupt:
        _say(f"interrupted: {len(store.lines)} cells stored in {store.out}; the same command runs the rest")
        return 130
    finally:
        store.close()
    blk = results_block(argv, args, store, time.perf_counter() - t, len(todo))
    print(brief(blk))
    print(f"wrote {write_results(args.out, args.stage, blk)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
