"""The last check before the arc on synthetic estimates: a fillet between an upright and a base plate, ending
against a post; a seam shifted across, too long, ending inside the post or running on past the upright fails with
its own code; one within the build's tolerance passes."""

from __future__ import annotations

import numpy as np
import pytest
from synthetic_joint import square_tube

from cell.geometry import make_pose
from cell.seams.checks import CHECK_SIGMAS, budget, last_check
from cell.types import Box, Joint, LastCheck, MapSeam, Part, SeamEstimate, SeamStatus


def _box(name: str, lo: list[float], hi: list[float]) -> Part:
    a, b = np.array(lo), np.array(hi)
    return Part(name, Box(make_pose(p=(a + b) / 2.0), b - a))


BASE = _box("BASE", [-0.2, -0.2, -0.01], [0.2, 0.2, 0.0])
UPRIGHT = _box("UPRIGHT", [-0.01, -0.05, 0.0], [0.0, 0.05, 0.1])
POST = _box("POST", [-0.02, 0.05, -0.01], [0.04, 0.09, 0.1])  # the seam's end runs against it
PARTS = (BASE, UPRIGHT, POST)
DRAWN = MapSeam("UPRIGHT>BASE:+x", np.array([0.0, -0.05, 0.0]), np.array([0.0, 0.05, 0.0]))
JOINT = Joint(DRAWN.id, "UPRIGHT", "BASE", "+x", "+z", "-z")
SIGMA = 1e-5
LIMITS = budget(0.006, 0.0, SIGMA)


def _est(start: list[float], end: list[float]) -> SeamEstimate:
    return SeamEstimate(DRAWN.id, SeamStatus.FOUND, "", np.array(start), np.array(end), 0.99, 0.0, SIGMA)


def test_the_budget_is_the_build_tolerance_the_calibration_and_the_estimates_sigma() -> None:
    b = budget(0.006, 0.001, 0.0002)
    own = 0.001 + CHECK_SIGMAS * 0.0002
    assert b.across_m == pytest.approx(0.012 + own)
    assert b.length_m == pytest.approx(0.006 + own)
    assert b.body_m == pytest.approx(0.003 + own)
    assert b.face_m == pytest.approx(0.012 + own)
    assert budget(0.006, 0.0, float("inf")).across_m == pytest.approx(0.012)  # no sigma: nothing added


def test_the_ends_sigmas_widen_the_length_and_the_faces_not_the_line() -> None:
    """An end placed only within a few mm (its sigma along the seam) is not failed for lying where its sigma says
    it may; the line across the seam keeps its budget."""
    b0, b = budget(0.006, 0.0, 0.0002), budget(0.006, 0.0, 0.0002, (0.0003, 0.0004))
    assert b.length_m == pytest.approx(b0.length_m + CHECK_SIGMAS * 0.0005)  # both ends in quadrature
    assert b.face_m == pytest.approx(b0.face_m + CHECK_SIGMAS * 0.0004)  # the larger end's
    assert (b.across_m, b.body_m) == (b0.across_m, b0.body_m)
    assert budget(0.006, 0.0, 0.0002, (float("inf"), float("inf"))) == b0  # none given: nothing added


def test_a_seam_where_the_map_draws_it_within_the_tolerance_passes() -> None:
    est = _est([0.004, -0.0495, 0.0003], [0.004, 0.0497, -0.0002])  # the upright built 4 mm off
    assert last_check(est, DRAWN, JOINT, PARTS, LIMITS) is None


def test_a_seam_shifted_across_fails_across() -> None:
    fail = last_check(_est([0.015, -0.05, 0.0], [0.016, 0.05, 0.0]), DRAWN, JOINT, PARTS, LIMITS)
    assert fail is not None and fail.code is LastCheck.ACROSS
    assert fail.value_m == pytest.approx(0.016) and fail.end == "end"
    assert fail.limit_m == pytest.approx(LIMITS.across_m)


def test_a_seam_too_long_fails_its_length() -> None:
    """The brace's 42 mm fillet located 60.6 mm long: its end ran on 18.6 mm along the receiving face."""
    fail = last_check(_est([0.0, -0.05, 0.0], [0.0, 0.0686, 0.0]), DRAWN, JOINT, PARTS, LIMITS)
    assert fail is not None and fail.code is LastCheck.LENGTH
    assert fail.value_m == pytest.approx(0.0186)


def test_an_end_inside_another_part_fails_with_that_part() -> None:
    fail = last_check(_est([0.0, -0.045, 0.0], [0.0, 0.0555, 0.0]), DRAWN, JOINT, PARTS, LIMITS)
    assert fail is not None and fail.code is LastCheck.END_IN_BODY
    assert fail.part == "POST" and fail.end == "end"
    assert fail.value_m == pytest.approx(0.0055, abs=2e-4)  # how deep in the post
    assert "end_in_body at its end (POST)" in fail.describe()


def test_an_end_past_the_abutting_part_fails_off_its_face() -> None:
    """Same length, same line, moved 13 mm along it: the end runs on past the upright (no post in the way)."""
    fail = last_check(_est([0.0, -0.037, 0.0], [0.0, 0.063, 0.0]), DRAWN, JOINT, (BASE, UPRIGHT), LIMITS)
    assert fail is not None and fail.code is LastCheck.END_OFF_FACE
    assert fail.part == "UPRIGHT" and fail.end == "end"
    assert fail.value_m == pytest.approx(0.013, abs=2e-4)


def test_a_seam_not_found_or_without_a_joint() -> None:
    missing = SeamEstimate(DRAWN.id, SeamStatus.NOT_FOUND)
    assert last_check(missing, DRAWN, JOINT, PARTS, LIMITS) is None
    # Without its joint every part is another: the ends on the upright's edge lie in no body deeper than 3 mm.
    assert last_check(_est([0.0, -0.05, 0.0], [0.0, 0.05, 0.0]), DRAWN, None, (BASE, UPRIGHT), LIMITS) is None


def test_an_end_run_on_into_a_tubes_bore_fails_in_a_body() -> None:
    """A tube standing on the base (its bottom level with the seam's line) against the upright's end: a seam
    located 5 mm on past the end (within the length budget), its end in the tube's bore. Neither end is inside
    the tube's body, but the bead along the seam passes its 2.6 mm wall: the end lies 5 mm beyond the face it
    enters."""
    tube = Part("TUBE", square_tube(np.array([0.0, 0.08, 0.0]), 0.06, 0.0026, 0.1))  # its outer wall at y = 0.05
    parts = (BASE, UPRIGHT, tube)
    est = _est([0.0, -0.05, 0.0], [0.0, 0.055, 0.0])
    assert not tube.contains(est.p_end[None])[0]  # in the bore, not in the wall
    fail = last_check(est, DRAWN, JOINT, parts, LIMITS)
    assert fail is not None and fail.code is LastCheck.END_IN_BODY
    assert fail.part == "TUBE" and fail.end == "end" and fail.value_m == pytest.approx(0.005, abs=4e-4)
    assert last_check(_est([0.0, -0.05, 0.0], [0.0, 0.0495, 0.0]), DRAWN, JOINT, parts, LIMITS) is None
