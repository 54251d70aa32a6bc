"""The sweep's engine: one Ray task per run, locally (a Ray started for this sweep, as many CPUs as the machine
or ``workers``) or on a running cluster (``address``), results handed back as they finish (``ray.wait``).

The only module of the cell that imports Ray (an import-linter contract). A task that raises or whose worker
dies comes back as a failed run (its error recorded), never as an exception that stops the others.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from cell.errors import UsageError
from cell.scenario import Scenario
from cell.sweep.task import Stage, error_json, run_task
from cell.sweep.variations import Variation

OnResult = Callable[[dict[str, Any]], None]
_OBJECT_STORE_BYTES = 256 * 2**20  # a local sweep's object store: a scenario and small dicts, not clouds


@dataclass(frozen=True)
class EngineInfo:
    """What ran the sweep: ``engine`` ("ray"), its version, where (``local`` or the address), the CPUs it had."""

    engine: str
    engine_version: str
    address: str
    cpus: int


def engine_version() -> str:
    """Ray's version, from its installed metadata (neither imported nor started: a sweep with nothing left to
    run needs no Ray)."""
    from importlib.metadata import version

    return version("ray")


def run_sweep(
    scenario: Scenario,
    todo: Sequence[Variation],
    stage: Stage,
    on_result: OnResult,
    *,
    method: str | None = None,
    address: str | None = None,
    workers: int | None = None,
    on_start: Callable[[EngineInfo], None] | None = None,
) -> EngineInfo:
    """Run every variation of ``todo`` as one Ray task (:func:`cell.sweep.task.run_task`), calling
    ``on_result(result)`` in the driver as each finishes (completion order). At most ``2 x CPUs`` tasks are in
    flight, so an interrupted sweep loses only those. ``address`` None starts a local Ray with ``workers`` CPUs
    (default: the machine's); else connects to that cluster (``host:port``). UsageError when it cannot."""
    import ray
    from ray.exceptions import RayError

    cpus_local = workers or os.cpu_count() or 1
    try:
        if address is None:
            ray.init(
                address="local",  # a Ray of its own, even when a cluster runs on this machine
                num_cpus=cpus_local,
                include_dashboard=False,
                log_to_driver=False,
                logging_level=logging.ERROR,
                object_store_memory=_OBJECT_STORE_BYTES,
            )
        else:
            ray.init(address=address, log_to_driver=False, logging_level=logging.ERROR)
    except (ConnectionError, RuntimeError, ValueError) as e:
        where = f"--address: cannot reach the Ray cluster at {address!r}" if address else "cannot start a local Ray"
        raise UsageError(f"{where} ({' '.join(str(e).split())[:200]})") from None
    try:
        cpus = int(ray.cluster_resources().get("CPU", cpus_local))
        info = EngineInfo("ray", str(ray.__version__), address or "local", cpus)
        if on_start is not None:
            on_start(info)
        remote = ray.remote(num_cpus=1, max_retries=1)(run_task)
        sc_ref = ray.put(scenario)
        limit = max(1, 2 * (workers or cpus))
        queue = list(todo)
        pending: dict[Any, Variation] = {}
        try:
            while queue or pending:
                while queue and len(pending) < limit:
                    v = queue.pop(0)
                    pending[remote.remote(sc_ref, v, stage, method)] = v
                done, _ = ray.wait(list(pending), num_returns=1)
                for ref in done:
                    v = pending.pop(ref)
                    try:
                        result = ray.get(ref)
                    except RayError as e:  # the worker died or the task could not run: a failed run
                        result = failed_result(v, e)
                    on_result(result)
        finally:
            for ref in pending:  # a cluster keeps running what it was given unless told otherwise
                ray.cancel(ref, force=True)
        return info
    finally:
        ray.shutdown()


def failed_result(v: Variation, e: BaseException) -> dict[str, Any]:
    """The result of a run whose task never returned (its worker died, Ray could not run it)."""
    return {"line": {"run": v.k, "variation": v.to_json(), "seams": {}, "error": error_json(e)}, "timings": {}}
