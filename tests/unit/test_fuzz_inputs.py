"""The fuzz of the file inputs, a seeded sample of it (the full count: ``benchmarks/bench_fuzz.py``): bad point
clouds and capture folders each answered in time by a clean result, warning lines or one CellError line, never a
traceback, and never an inconsistent file read without a word."""

from __future__ import annotations

import time
from collections import Counter

import pytest
from tools_loader import load_bench

CASE_S = 5.0  # [s] a case over this counts as a hang (each takes under 0.3 s on the 2-core machine)


@pytest.mark.parametrize(("kind", "count"), [("clouds", 66), ("captures", 18)])
def test_a_fuzz_sample_gets_one_line_answers(kind: str, count: int) -> None:
    bench = load_bench("bench_fuzz")
    run = bench.cloud_outcomes if kind == "clouds" else bench.capture_outcomes
    start = time.perf_counter()
    outcomes = list(run(seed=1, count=count, timeout_s=CASE_S))  # another seed than the committed results' 0
    assert len(outcomes) == count and time.perf_counter() - start < count * 1.0
    wrong = [(o.name, o.violation, o.lines) for o in outcomes if o.violation is not None]
    assert not wrong
    kinds = Counter(o.kind for o in outcomes)
    assert kinds["error"] > count // 3 and kinds["clean"] >= count // 11  # both refusals and valid files seen
    if kind == "clouds":
        assert kinds["warned"] > count // 10  # duplicates, NaN rows, stray returns, stray bytes
    for o in outcomes:
        assert all(line.count("\n") == 0 for line in o.lines) and o.seconds < CASE_S


def test_the_runner_calls_a_traceback_and_a_silent_acceptance_violations() -> None:
    bench = load_bench("bench_fuzz")

    def broken(warn: object) -> None:
        raise ValueError("buffer size must be a multiple of element size")

    assert bench.answer("x/broken/0", "any", broken, CASE_S).violation == "traceback"
    silent = bench.answer("x/quiet/0", "flag", lambda warn: None, CASE_S)
    assert silent.kind == "clean" and silent.violation == "inconsistent file accepted without a warning"
    assert bench.answer("x/slow/0", "any", lambda warn: time.sleep(2.0), 0.2).kind == "hang"
