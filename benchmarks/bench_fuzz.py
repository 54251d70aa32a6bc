"""Fuzz of the cell's file inputs: bad point clouds for ``read_cloud`` and bad capture folders for ``read_capture``,
made from a seed, each answered within a time bound by a clean result, a warning line or one CellError line.

    .venv/bin/python benchmarks/bench_fuzz.py --kind clouds|captures [--count N] [--seed S] [--json PATH]

Per case the outcome is ``error`` (a CellError, its one-line message), ``warned`` (read, with warning lines),
``clean`` (read without a word), ``traceback`` (any other exception) or ``hang`` (over ``--timeout`` seconds).
A violation is a traceback, a hang, an answer of more than one line, an inconsistent file (``flag``) read
without a warning, or a valid file (``clean``) refused or warned about. The peak memory is the process's
(``resource.getrusage``). The figures go to ``--json`` (default ``benchmarks/results/fuzz_inputs.json``, one
entry per kind); the exit code is 1 when any case is a violation. The generators: ``fuzz_clouds.py``,
``fuzz_captures.py``.
"""

from __future__ import annotations

import argparse
import json
import resource
import signal
import sys
import tempfile
import time
import warnings
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from types import FrameType
from typing import Any

BENCH = Path(__file__).resolve().parent
if str(BENCH) not in sys.path:  # its sibling modules, also when loaded by path (the tests)
    sys.path.insert(0, str(BENCH))

import fuzz_captures  # noqa: E402
import fuzz_clouds  # noqa: E402

from cell.errors import CellError  # noqa: E402

RESULTS = BENCH / "results" / "fuzz_inputs.json"
COUNTS = {"clouds": 432, "captures": 111}  # as many as the outsider's fuzz that found the gaps
TIMEOUT_S = 20.0


@dataclass(frozen=True)
class Outcome:
    """How one case was answered: ``kind`` (error, warned, clean, traceback, hang), the lines said, the time."""

    name: str
    expect: str
    kind: str
    lines: tuple[str, ...]
    seconds: float

    @property
    def violation(self) -> str | None:
        """Why this answer is wrong (None when it is right)."""
        if self.kind in ("traceback", "hang"):
            return self.kind
        if any("\n" in line or not line.strip() for line in self.lines):
            return "not one line"
        if self.expect == "flag" and self.kind == "clean":
            return "inconsistent file accepted without a warning"
        if self.expect == "clean" and self.kind != "clean":
            return "valid file refused or warned about"
        return None


class _HangError(Exception):
    pass


def _alarm(signum: int, frame: FrameType | None) -> None:
    raise _HangError


def answer(name: str, expect: str, read: Callable[..., object], timeout_s: float) -> Outcome:
    """Run ``read(warn=...)`` once under a time bound and classify what it did."""
    said: list[str] = []
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout_s)
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            read(warn=said.append)
        said += [str(w.message) for w in caught]
        kind = "warned" if said else "clean"
    except _HangError:
        kind = "hang"
    except CellError as e:
        kind, said = "error", [*said, e.message]
    except Exception as e:  # what the fuzz is looking for
        kind, said = "traceback", [*said, f"{type(e).__name__}: {e}"]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)
    return Outcome(name, expect, kind, tuple(said), time.perf_counter() - start)


def cloud_outcomes(seed: int, count: int, timeout_s: float = TIMEOUT_S) -> Iterator[Outcome]:
    """Each fuzzed cloud read by ``read_cloud`` (see the module docstring)."""
    from cell.perception.cloud_files import read_cloud

    with tempfile.TemporaryDirectory() as tmp:
        for case in fuzz_clouds.cases(seed, count, Path(tmp)):
            path = Path(tmp) / "cloud.dat"
            path.write_bytes(case.data)
            yield answer(case.name, case.expect, partial(read_cloud, path), timeout_s)


def capture_outcomes(seed: int, count: int, timeout_s: float = TIMEOUT_S) -> Iterator[Outcome]:
    """Each fuzzed capture folder read by ``read_capture`` (see the module docstring)."""
    from cell.recorded import read_capture

    with tempfile.TemporaryDirectory() as tmp:
        for case in fuzz_captures.cases(seed, count, Path(tmp)):
            yield answer(case.name, case.expect, partial(_read_capture, read_capture, case.folder), timeout_s)


def _read_capture(read: Callable[[Path], object], folder: Path, warn: Callable[[str], None]) -> object:
    return read(folder)  # read_capture says nothing but errors: ``warn`` is not used


def summary(kind: str, seed: int, outcomes: Sequence[Outcome], wall_s: float) -> dict[str, Any]:
    """The figures of one kind's run (what ``--json`` holds per kind)."""
    bad = [o for o in outcomes if o.violation is not None]
    why = Counter(o.violation for o in bad)
    by_mutation: dict[str, Counter[str]] = {}
    for o in outcomes:
        by_mutation.setdefault(o.name.split("/")[-2], Counter())[o.kind] += 1
    return {
        "kind": kind,
        "seed": seed,
        "cases": len(outcomes),
        "outcomes": dict(Counter(o.kind for o in outcomes)),
        "expected": dict(Counter(o.expect for o in outcomes)),
        "tracebacks": why["traceback"],
        "hangs": why["hang"],
        "not_one_line": why["not one line"],
        "inconsistent_accepted_silently": why["inconsistent file accepted without a warning"],
        "valid_refused": why["valid file refused or warned about"],
        "slowest_s": round(max((o.seconds for o in outcomes), default=0.0), 3),
        "wall_s": round(wall_s, 1),
        "peak_memory_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1),
        "by_mutation": {m: dict(c) for m, c in sorted(by_mutation.items())},
        "violations": [{"case": o.name, "why": o.violation, "said": list(o.lines)} for o in bad],
    }


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--kind", choices=sorted(COUNTS), required=True)
    parser.add_argument("--count", type=int, default=None, help="cases (default: 432 clouds, 111 captures)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=TIMEOUT_S, help="seconds a case may take before a hang")
    parser.add_argument("--json", type=Path, default=RESULTS)
    args = parser.parse_args(argv)
    count = args.count or COUNTS[args.kind]
    run = cloud_outcomes if args.kind == "clouds" else capture_outcomes
    start = time.perf_counter()
    outcomes = list(run(args.seed, count, args.timeout))
    result = summary(args.kind, args.seed, outcomes, time.perf_counter() - start)
    saved = json.loads(args.json.read_text()) if args.json.is_file() else {}
    saved[args.kind] = result | {"command": f"benchmarks/bench_fuzz.py --kind {args.kind} --seed {args.seed}"}
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(saved, indent=1, sort_keys=True) + "\n")
    shown = {k: result[k] for k in ("cases", "outcomes", "tracebacks", "hangs", "not_one_line")}
    shown |= {k: result[k] for k in ("inconsistent_accepted_silently", "valid_refused", "slowest_s", "peak_memory_mb")}
    print(json.dumps(shown))
    for v in result["violations"]:
        print(f"{v['case']}: {v['why']}: {' | '.join(v['said'])[:300]}")
    return 1 if result["violations"] else 0


if __name__ == "__main__":
    sys.exit(main())
