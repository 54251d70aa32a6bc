"""Close-up views ranked lazily (the line-of-sight test only on the candidates asked for) are the same views in
the same order, and a close-up taken for one seam is tested for another seam with every test a view of its own
must pass (cell.rescan.view_grid.sees), so one image can serve several seams."""

from __future__ import annotations

import math
from itertools import islice

import numpy as np
import pytest
from tiny_cell import TOP_SEAM, URDF

from cell.geometry import make_pose
from cell.motion.robot import RobotModel
from cell.rescan.view_grid import (
    ViewCandidate,
    ViewTarget,
    ranked_views,
    sees,
    torch_axis_in_camera,
    view_candidates,
)
from cell.sim.camera import intrinsics_for
from cell.types import Box, Part

K = intrinsics_for(1280, 720, math.radians(65.0))  # the D415 of the scenarios
TOP = ViewTarget(*TOP_SEAM)
# The same seam 80 mm further along x (a neighbouring rung's), and a block standing over the first seam's +y side.
ALONG = np.array([0.08, 0.0, 0.0])
NEXT = ViewTarget("next", TOP.p_start + ALONG, TOP.p_end + ALONG, TOP.n_a, TOP.n_b)
BLOCK = Part("BLOCK", Box(make_pose(p=[0.0, 0.72, 0.2]), np.array([0.3, 0.05, 0.05])))


@pytest.fixture(scope="module")
def torch_C() -> np.ndarray:
    return torch_axis_in_camera(RobotModel.from_urdf(URDF))


@pytest.fixture(scope="module")
def free(torch_C: np.ndarray) -> list[ViewCandidate]:
    """The views of the first seam with nothing in the way, best first."""
    return view_candidates(TOP, K, torch_C, (), 0.0)


def _key(c: object) -> tuple[float, ...]:
    return tuple(np.round(c.X_RC, 12).ravel())  # type: ignore[attr-defined]


def test_lazy_ranking_is_the_filtered_ranking(torch_C: np.ndarray, free: list[ViewCandidate]) -> None:
    blocked = view_candidates(TOP, K, torch_C, (BLOCK,), 0.0)
    assert len(free) > len(blocked) > 0  # the block hides some views, not all
    assert [c.score for c in free] == sorted(c.score for c in free)
    # the views the block leaves, in the order they had without it
    assert [_key(c) for c in blocked] == [_key(c) for c in free if sees(c.X_RC, TOP, K, torch_C, (BLOCK,), 0.0)]
    assert [_key(c) for c in islice(ranked_views(TOP, K, torch_C, (BLOCK,), 0.0), 3)] == [_key(c) for c in blocked[:3]]


def test_a_view_sees_its_own_seam_with_its_incidence(torch_C: np.ndarray, free: list[ViewCandidate]) -> None:
    for c in free[:5]:
        assert sees(c.X_RC, TOP, K, torch_C, (), 0.0) == pytest.approx(c.incidence)


def test_a_close_up_may_serve_a_neighbouring_seam_but_not_a_hidden_one(
    torch_C: np.ndarray, free: list[ViewCandidate]
) -> None:
    views = free
    shared = [c for c in views if sees(c.X_RC, NEXT, K, torch_C, (), 0.0) is not None]
    assert 0 < len(shared) < len(views)  # some views of the first seam show the second one whole, not all
    far = ViewTarget("far", TOP.p_start + 6.0 * ALONG, TOP.p_end + 6.0 * ALONG, TOP.n_a, TOP.n_b)
    assert all(sees(c.X_RC, far, K, torch_C, (), 0.0) is None for c in views)  # out of the image
    hidden = [c for c in shared if sees(c.X_RC, NEXT, K, torch_C, (BLOCK,), 0.0) is None]
    assert hidden  # the block stands between some of those views and the second seam


def test_a_seam_with_no_sample_above_the_table_is_seen_by_no_view(
    torch_C: np.ndarray, free: list[ViewCandidate]
) -> None:
    """A seam estimate under the table top (a missing part's seam, faults/missing-part): nothing to see, no view (it
    raised on an empty array when a close-up of another seam was tested for it)."""
    low = ViewTarget("low", TOP.p_start - [0.0, 0.0, 0.5], TOP.p_end - [0.0, 0.0, 0.5], TOP.n_a, TOP.n_b)
    assert sees(free[0].X_RC, low, K, torch_C, (), float(TOP.p_start[2])) is None
    assert list(ranked_views(low, K, torch_C, (), float(TOP.p_start[2]))) == []
