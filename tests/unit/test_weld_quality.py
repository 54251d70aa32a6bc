"""The weld measured whole: how far the TCP strays from the true seam, and how much of the joint the bead leaves
unwelded or overruns at each end, whichever way it ran and over every pass."""

from __future__ import annotations

import numpy as np
import pytest

from cell.process.quality import combined, distance_to_segment, end_coverage, weld_quality
from cell.types.execution import WeldQuality

A = np.array([0.1, 0.2, 0.0])
B = np.array([0.1, 0.3, 0.0])  # a 100 mm joint along +y


def _bead(s0: float, s1: float, n: int = 101, lateral: float = 0.0) -> np.ndarray:
    """TCP records from s0 to s1 [m] along the joint's line, ``lateral`` [m] off it along x."""
    s = np.linspace(s0, s1, n)
    return A + s[:, None] * np.array([0.0, 1.0, 0.0]) + lateral * np.array([1.0, 0.0, 0.0])


def _quality(p: np.ndarray) -> WeldQuality:
    return weld_quality(np.linspace(0.0, 10.0, len(p)), p, A, B)


def test_a_bead_shorter_than_its_joint_is_short_at_both_ends() -> None:
    q = _quality(_bead(0.003, 0.0985))
    assert q.short_start_mm == pytest.approx(3.0, abs=1e-9)
    assert q.short_end_mm == pytest.approx(1.5, abs=1e-9)
    assert q.past_start_mm == 0.0 and q.past_end_mm == 0.0
    assert q.tcp_max_mm == pytest.approx(0.0, abs=1e-9)  # on the seam all along: the TCP error alone says nothing
    assert q.ends_mm == pytest.approx(3.0)


def test_a_bead_longer_than_its_joint_runs_past_and_counts_its_distance_to_the_end() -> None:
    q = _quality(_bead(-0.002, 0.1186))
    assert q.past_start_mm == pytest.approx(2.0, abs=1e-9)
    assert q.past_end_mm == pytest.approx(18.6, abs=1e-9)
    assert q.short_start_mm == 0.0 and q.short_end_mm == 0.0
    # A record beyond an end is as far from the seam as from that end: the TCP max sees the overrun too.
    assert q.tcp_max_mm == pytest.approx(18.6, abs=1e-9)


def test_distance_beyond_an_end_is_the_distance_to_that_end() -> None:
    p = np.array([[0.1, 0.31, 0.003], [0.1, 0.25, 0.004], [0.1, 0.19, 0.0]])
    d = distance_to_segment(p, A, B)
    assert d == pytest.approx([np.hypot(0.01, 0.003), 0.004, 0.01])


def test_a_reversed_bead_is_judged_against_the_joints_own_ends() -> None:
    q = _quality(_bead(0.0995, 0.004))  # welded from the end to the start, stopping 4 mm short of the start
    assert q.short_start_mm == pytest.approx(4.0, abs=1e-9)
    assert q.short_end_mm == pytest.approx(0.5, abs=1e-9)
    assert q.past_start_mm == 0.0 and q.past_end_mm == 0.0


def test_offsets_are_taken_off_before_the_ends_are_measured() -> None:
    p = _bead(0.0, 0.1, lateral=0.002)  # a pass 2 mm off the root, as planned
    offsets = np.tile([0.002, 0.0, 0.0], (len(p), 1))
    q = weld_quality(np.linspace(0.0, 10.0, len(p)), p, A, B, offsets)
    assert q.tcp_max_mm == pytest.approx(0.0, abs=1e-9)
    assert q.ends_mm == pytest.approx(0.0, abs=1e-9)


def test_multi_pass_takes_each_ends_worst_pass() -> None:
    root = _quality(_bead(0.001, 0.1))
    cap = _quality(_bead(-0.0015, 0.097))
    both = combined([root, cap])
    assert both.short_start_mm == pytest.approx(1.0)
    assert both.past_start_mm == pytest.approx(1.5)
    assert both.short_end_mm == pytest.approx(3.0)
    assert both.past_end_mm == pytest.approx(0.0, abs=1e-9)
    assert both.samples == root.samples + cap.samples


def test_end_coverage_of_a_bead_wholly_beyond_one_end() -> None:
    short_start, short_end, past_start, past_end = end_coverage(_bead(0.11, 0.12, n=5), A, B)
    assert short_start == pytest.approx(0.11) and past_end == pytest.approx(0.02)
    assert short_end == 0.0 and past_start == 0.0
