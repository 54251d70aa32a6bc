"""Our locator on thin plates (cell.seams.ours): bands no wider than a share of a thin face, and a side face of the
abutting part that lies against another part's face (hidden) marked so that face's points place the end."""

from __future__ import annotations

import numpy as np
import pytest

from cell.geometry import make_pose
from cell.seams.ours._bodies import touch_gap
from cell.seams.ours._geometry import THIN_SHARE, JointGeometry, within
from cell.types import Box, Joint, Part


def test_bands_shrink_on_thin_faces_only() -> None:
    assert within(0.011, 0.008) == pytest.approx(THIN_SHARE * 0.008)  # an 8 mm lap plate's side keeps a window
    assert 0.008 - within(0.010, 0.008) > within(0.011, 0.008)
    for band in (0.004, 0.005, 0.010, 0.011):  # every band the locator cuts, on faces 44 mm and taller: unchanged
        assert within(band, 0.044) == band and within(band, 0.0508) == band and within(band, 0.8) == band


def _upright_and_gusset() -> tuple[Part, Part, Part]:
    """A base plate (top at z = 0.012), an upright standing on it (its -x face at x = 0.2) and a gusset box between
    the base and the upright, its back (+x) on the upright and its foot (-z) on the base."""
    base = Part("BASE", Box(make_pose(p=(0.2, 0.125, 0.006)), np.array([0.4, 0.25, 0.012])))
    upright = Part("UPRIGHT", Box(make_pose(p=(0.206, 0.125, 0.096)), np.array([0.012, 0.2, 0.168])))
    gusset = Part("GUSSET", Box(make_pose(p=(0.15, 0.125, 0.062)), np.array([0.1, 0.012, 0.1])))
    return base, upright, gusset


def test_a_side_face_on_another_part_is_touching_where_the_seam_ends() -> None:
    base, upright, gusset = _upright_and_gusset()
    n_back, d_back = gusset.face_plane("+x")
    assert touch_gap(upright, n_back, d_back, np.array([0.2, 0.119, 0.012])) == pytest.approx(0.0)
    assert touch_gap(upright, n_back, d_back - 0.001, np.array([0.2, 0.119, 0.012])) == pytest.approx(
        0.001
    )  # drawn 1 mm off
    assert (
        touch_gap(upright, n_back, d_back, np.array([0.2, 0.119, 0.3])) is None
    )  # the plane, but off the upright there
    assert touch_gap(base, n_back, d_back, np.array([0.2, 0.119, 0.012])) is None  # no face of the base in that plane
    # The gusset-to-base seam along its -y face: from the upright (x = 0.2) to the toe (x = 0.1).
    joint = Joint("G", "GUSSET", "BASE", "-y", "+z", "-z")
    p0, t = np.array([0.2, 0.119, 0.012]), np.array([-1.0, 0.0, 0.0])
    geo = JointGeometry.of(gusset, base, joint, p0, t, (0.0, 0.1), 0.004)
    start, end = geo.end_planes(t, [0.0, 0.1], 0.0, 0.006, (base, upright), p0)
    assert start.touching == pytest.approx(0.012) and start.gap == pytest.approx(
        0.0, abs=1e-12
    )  # the upright, 12 mm thick behind its face
    assert end.touching == 0.0  # the toe's face is free
    plain = geo.end_planes(t, [0.0, 0.1], 0.0, 0.006)  # no other parts given: nothing touches
    assert plain[0].touching == 0.0 and plain[1].touching == 0.0
