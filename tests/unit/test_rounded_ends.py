"""Where a seam on a rounded tube ends, for our locator (docs/bodies.md section 8): short of the side flat (or the
table) by the corner radius the map's end lies inside it, and, with no side seen, at the tangent line where the
flat turns into the radius (cell/seams/ours/_ends.py, _geometry.py, _bodies.py)."""

from __future__ import annotations

import numpy as np
import pytest

from cell import scenario as sc
from cell.seams.joint import find_joints
from cell.seams.ours._ends import tangent_end
from cell.seams.ours._geometry import JointGeometry, line
from cell.seams.ours._planes import End
from cell.types import WeldMap
from cell.weldmap import read_map

RADIUS = 0.006  # [m] the posts' and the bottom rail's outer corner radius (3 mm walls)


@pytest.fixture(scope="module")
def rhs_map() -> WeldMap:
    return read_map(sc.load("rhs").map_path)


def _ends(weldmap: WeldMap, seam_id: str) -> tuple[End, End]:
    """The end planes our locator starts from for a seam of the rhs map as drawn (table top at z = 0)."""
    joint = find_joints(weldmap)[seam_id]
    seam = next(s for s in weldmap.seams if s.id == seam_id)
    a, b = weldmap.part(joint.abutting), weldmap.part(joint.receiving)
    n_a, d_a = a.face_plane(joint.face_abutting)
    n_b, d_b = b.face_plane(joint.face_receiving)
    p0, t = line(n_a, d_a, n_b, d_b, 0.5 * (seam.p_start + seam.p_end), seam.direction)
    s_map = sorted((float(t @ (seam.p_start - p0)), float(t @ (seam.p_end - p0))))
    geo = JointGeometry.of(a, b, joint, p0, t, (s_map[0], s_map[1]), 0.004)
    others = tuple(p for p in weldmap.parts if p.name != a.name)
    ends = geo.end_planes(t, s_map, 0.0, 0.006, others, p0)
    for end in ends:  # the side flats are wholly across the line, not a facet of the radius before them
        assert abs(float(end.n @ t)) == pytest.approx(1.0, abs=1e-6)
    return ends


def test_a_vertical_seam_starts_above_the_table_by_the_rails_radius_and_ends_short_of_the_posts_top(
    rhs_map: WeldMap,
) -> None:
    start, end = _ends(
        rhs_map, "POST_L>TOP_RAIL:+x"
    )  # up the post's side, against the top rail (4 mm wall, radius 8 mm)
    assert start.on_table and start.inset == pytest.approx(0.008, abs=1e-9)
    assert not end.on_table and end.n[2] == pytest.approx(1.0) and end.inset == pytest.approx(RADIUS, abs=1e-9)


def test_a_seam_across_a_tubes_top_ends_short_of_both_side_flats_by_its_radius(rhs_map: WeldMap) -> None:
    for end in _ends(rhs_map, "BOTTOM_RAIL>POST_L:+z"):
        assert not end.on_table and end.inset == pytest.approx(RADIUS, abs=1e-9)


def test_the_tangent_line_is_found_where_the_flat_turns_into_the_radius() -> None:
    """Points on a flat up to s0, then round a 6 mm corner, with 0.12 mm noise (a close-up's): the profile fit finds
    s0 within a tenth of a millimetre, where the points within the gate of the plane run about 1.5 mm further."""
    rng = np.random.default_rng(7)
    s0, sigma = 0.020, 1.2e-4
    s = rng.uniform(0.0, s0 + RADIUS, 4000)
    h = np.clip(s - s0, 0.0, RADIUS)
    r = -(RADIUS - np.sqrt(RADIUS**2 - h**2)) + rng.normal(0.0, sigma, len(s))
    near = s[np.abs(r) < 2.5 * sigma]
    assert np.quantile(near, 0.999) - s0 > 0.001  # what the extent of the points near the plane reads
    found, se = tangent_end(s, r, float(near.max()), RADIUS, sigma)
    assert abs(found - s0) < 1e-4
    assert sigma <= se < 3 * sigma
