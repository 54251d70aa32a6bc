"""The RANSAC baseline and our map-guided locator on the synthetic T joint of tests/synthetic_joint.py (ray-cast
depth cameras, as-built parts a few mm off the map, so a locator that returns the map's seam fails).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from synthetic_joint import (
    AS_BUILT,
    CASES,
    SIDE,
    TOP,
    Render,
    a_taller,
    errors,
    make_scene,
    scene_with,
    thinned,
    voxel_cloud,
)

from cell.geometry import make_pose, rot_z
from cell.seams import _extent, _lines
from cell.seams.ours import OursLocator, OursOptions
from cell.seams.ransac import RansacLocator, RansacOptions
from cell.types import Box, Reason, SeamScene, SeamStatus


@pytest.fixture(scope="module")
def scenes() -> dict[str, tuple[SeamScene, dict]]:
    return {name: make_scene(X, opts, seed=i) for i, (name, (X, opts)) in enumerate(CASES.items())}


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("seam_id", [TOP, SIDE])
def test_ours_finds_seams_in_any_orientation(scenes: dict, case: str, seam_id: str) -> None:
    scene, truth = scenes[case]
    seam = scene.weldmap.seam(seam_id)
    map_lat, _ = errors(seam.p_start, seam.p_end, truth[seam_id])
    assert map_lat > 0.001  # the map alone is more than 1 mm off: the test can fail
    est = OursLocator().locate(scene, seam, np.random.default_rng(0))
    assert est.status is SeamStatus.FOUND, est.reason
    lat, along = errors(est.p_start, est.p_end, truth[seam_id])
    assert lat < 0.0005, f"lateral {lat * 1000:.2f} mm"
    assert along < 0.002, f"ends {along * 1000:.2f} mm"
    assert 0.3 < est.confidence <= 1.0


def test_ours_noise_free_is_exact() -> None:
    scene, truth = make_scene(opts=Render(sigma_m=0.0, flying=0.0))
    for seam_id in (TOP, SIDE):
        est = OursLocator().locate(scene, scene.weldmap.seam(seam_id), np.random.default_rng(0))
        lat, along = errors(est.p_start, est.p_end, truth[seam_id])
        assert lat < 0.0001 and along < 0.001, (seam_id, lat, along)


def test_ours_confidence_falls_with_support_and_missing_face_is_not_found(scenes: dict) -> None:
    scene, _ = scenes["axis-aligned"]
    seam = scene.weldmap.seam(TOP)
    full = OursLocator().locate(scene, seam, np.random.default_rng(0))
    keep = np.random.default_rng(1).random(len(scene.dense)) > 0.7
    thin = OursLocator().locate(thinned(scene, keep), seam, np.random.default_rng(0))
    assert thin.status is SeamStatus.FOUND
    assert thin.confidence < full.confidence - 0.05, (full.confidence, thin.confidence)
    # Remove face B (the rail's -y face) entirely.
    n_b, d_b = scene.weldmap.part("B").box.face_plane("-y")
    off_b = np.abs(scene.dense.points @ n_b - d_b) > 0.012
    gone = OursLocator().locate(thinned(scene, off_b), seam, np.random.default_rng(0))
    assert gone.status is SeamStatus.NOT_FOUND and gone.code is Reason.NO_SUPPORT
    assert "B -y" in gone.reason


def test_ours_is_deterministic(scenes: dict) -> None:
    scene, _ = scenes["rotated 30 deg about z"]
    seam = scene.weldmap.seam(SIDE)
    opts = OursOptions(max_points=3000)  # forces the random subsample
    e1 = OursLocator(opts).locate(scene, seam, np.random.default_rng(5))
    e2 = OursLocator(opts).locate(scene, seam, np.random.default_rng(5))
    assert np.array_equal(e1.p_start, e2.p_start) and np.array_equal(e1.p_end, e2.p_end)
    assert e1.confidence == e2.confidence


@pytest.mark.parametrize("case", list(CASES))
def test_ours_finds_seams_together_as_it_does_one_by_one(scenes: dict, case: str) -> None:
    """locate_many batches the plane fits of all seams of a pass; each seam's answer must not change (the
    batched IRLS iterates until every plane has settled: within a micrometre)."""
    scene, _ = scenes[case]
    seams = [scene.weldmap.seam(TOP), scene.weldmap.seam(SIDE)]
    together = OursLocator().locate_many(scene, seams, np.random.default_rng(0))
    for seam, est in zip(seams, together, strict=True):
        alone = OursLocator().locate(scene, seam, np.random.default_rng(0))
        assert est.id == seam.id and est.status is alone.status is SeamStatus.FOUND
        assert np.allclose(est.p_start, alone.p_start, atol=1e-6) and np.allclose(est.p_end, alone.p_end, atol=1e-6)
        assert abs(est.confidence - alone.confidence) < 0.01


def test_ours_places_an_unseen_face_from_its_edge(scenes: dict) -> None:
    """A's top face unseen (as a face at grazing incidence drops out): its plane comes from where A's side
    faces end; with those edges gone too, the seam is NOT_FOUND naming the face."""
    scene, truth = scenes["axis-aligned"]
    seam = scene.weldmap.seam(TOP)
    full = OursLocator().locate(scene, seam, np.random.default_rng(0))
    hidden, _ = make_scene(CASES["axis-aligned"][0], Render(hide_top_of="A"), seed=0)
    est = OursLocator().locate(hidden, seam, np.random.default_rng(0))
    assert est.status is SeamStatus.FOUND, est.reason
    assert "face A +z from the edge of" in est.reason
    lat, _ = errors(est.p_start, est.p_end, truth[TOP])
    map_lat, _ = errors(seam.p_start, seam.p_end, truth[TOP])
    assert lat < 0.6 * map_lat and lat < 0.001, f"lateral {lat * 1000:.2f} mm (map {map_lat * 1000:.2f} mm)"
    assert est.confidence < full.confidence
    box_a = hidden.weldmap.part("A").box
    n_top, d_top = box_a.face_plane("+z")
    rim = ((hidden.dense.points @ n_top - d_top) > -0.015) & box_a.contains(hidden.dense.points, margin=0.01)
    gone = OursLocator().locate(thinned(hidden, ~rim), seam, np.random.default_rng(0))
    assert gone.status is SeamStatus.NOT_FOUND and gone.code is Reason.NO_SUPPORT
    assert "face A +z" in gone.reason and "edge" in gone.reason


def test_ours_places_an_unseen_face_whose_edge_lies_beyond_the_map_tolerance() -> None:
    """Regression: A 8.7 mm taller than the map (tolerance 6 mm), its top unseen. The edge was searched only
    within the tolerance, where the selected points stopped, and the face landed ~3 mm off at the usual
    confidence (faults/camera-dead, POST_L's -x face)."""
    scene, truth = scene_with(a_taller(0.008), Render(hide_top_of="A"))
    seam = scene.weldmap.seam(TOP)
    est, err = OursLocator().locate_with_errors(scene, seam, np.random.default_rng(0))
    assert est.status is SeamStatus.FOUND, est.reason
    assert "face A +z from the edge of" in est.reason
    lat, _ = errors(est.p_start, est.p_end, truth[TOP])
    assert lat < 0.5e-3 and lat < 3.0 * err.lateral_m, (lat, err)


@pytest.mark.parametrize(
    ("boxes", "render_opts", "why"),
    [
        (a_taller(0.014), Render(hide_top_of="A"), "lies at the limit of the 12 mm searched"),
        (AS_BUILT, Render(hide_top_of="A", sigma_m=0.006), "is blurred over 2.5 mm"),
    ],
    ids=["edge beyond the search", "edge seen blurred"],
)
def test_ours_refuses_an_unseen_face_whose_edge_is_not_defined(
    boxes: dict[str, Box], render_opts: Render, why: str
) -> None:
    scene, _ = scene_with(boxes, render_opts)
    est = OursLocator().locate(scene, scene.weldmap.seam(TOP), np.random.default_rng(0))
    assert est.status is SeamStatus.NOT_FOUND and est.code is Reason.NO_SUPPORT
    assert "face A +z is seen by no usable camera" in est.reason
    assert "its edge is not defined well enough" in est.reason and why in est.reason, est.reason


def test_ours_edge_placed_face_carries_its_edge_standard_error(scenes: dict) -> None:
    scene, truth = scenes["axis-aligned"]
    seam = scene.weldmap.seam(TOP)
    full, e_full = OursLocator().locate_with_errors(scene, seam, np.random.default_rng(0))
    hidden, _ = make_scene(CASES["axis-aligned"][0], Render(hide_top_of="A"), seed=0)
    est, e_edge = OursLocator().locate_with_errors(hidden, seam, np.random.default_rng(0))
    assert est.status is SeamStatus.FOUND and full.status is SeamStatus.FOUND
    # The edge defines the face far less well than its own points do: a larger error, a lower confidence.
    assert e_edge.face_a_m > 3.0 * e_full.face_a_m and e_edge.lateral_m > 3.0 * e_full.lateral_m
    assert np.isclose(e_edge.face_b_m, e_full.face_b_m, rtol=0.5)
    assert est.confidence < 0.5 * full.confidence
    lat, _ = errors(est.p_start, est.p_end, truth[TOP])
    assert lat < 3.0 * e_edge.lateral_m, (lat, e_edge.lateral_m)
    assert f"+-{1000 * e_edge.face_a_m:.2f} mm" in est.reason
    gone = OursLocator().locate_with_errors(hidden, hidden.weldmap.seam(TOP), np.random.default_rng(0))
    assert gone[1] == e_edge  # deterministic


def test_ours_takes_no_end_where_the_cloud_stops(scenes: dict) -> None:
    """A's +x end beyond the workspace's crop: its top's points run to the crop, which is not the part's end
    (was: a short seam ending at the crop)."""
    scene, _ = scenes["axis-aligned"]
    seam = scene.weldmap.seam(TOP)
    x_cut = float(CASES["axis-aligned"][0][0, 3]) + 0.02  # through A (x 0.262..0.342 m)
    cut = thinned(scene, scene.dense.points[:, 0] < x_cut)
    est = OursLocator().locate(cut, seam, np.random.default_rng(0))
    assert est.status is SeamStatus.NOT_FOUND and est.code is Reason.NO_SUPPORT
    assert "the seam's end is not seen" in est.reason and "workspace" in est.reason, est.reason
    # Given the workspace, the same; a workspace that the cloud does not reach is not a cut.
    lo, hi = np.array([-1.0, -1.0, -1.0]), np.array([x_cut, 1.0, 2.0])
    ws = Box(make_pose(p=(lo + hi) / 2.0), hi - lo)
    est = OursLocator(OursOptions(workspace_R=ws)).locate(cut, seam, np.random.default_rng(0))
    assert est.status is SeamStatus.NOT_FOUND and est.code is Reason.NO_SUPPORT and "workspace" in est.reason
    hi_wide = np.array([x_cut + 0.2, 1.0, 2.0])
    wide = Box(make_pose(p=(lo + hi_wide) / 2.0), hi_wide - lo)
    thin = OursLocator(OursOptions(workspace_R=wide)).locate(cut, seam, np.random.default_rng(0))
    assert thin.status is not SeamStatus.NOT_FOUND or "workspace" not in thin.reason


def test_edge_fit_finds_a_blurred_edge_and_flags_a_cut_off() -> None:
    rng = np.random.default_rng(4)
    s = rng.uniform(-0.03, 0.0021, 3000) + 0.0005 * rng.standard_normal(3000)
    f = _extent.edge_fit(s, -0.024, 0.0235, -0.012, 0.012)
    assert f.ok and abs(f.b - 0.0021) < 3.0 * f.se + 1e-4 and f.blur <= 1e-3 and f.n_edge > 50
    # The same points cut off at 1 mm (a crop or a selection) inside a search that reaches 2 mm: an edge at the
    # cut would be wrong; it is flagged when the window ends there.
    cut = s[s < 0.001]
    assert _extent.edge_fit(cut, -0.024, 0.001, -0.012, 0.012).at_limit
    # Searched only up to 0.5 mm: the density does not end inside the search.
    assert _extent.edge_fit(s, -0.024, 0.0235, -0.012, 0.0005).at_limit


@pytest.mark.xfail(
    strict=True,
    reason="the edge model's exact normaliser finds this edge, but also placed a random cell's face from an edge "
    "2.1 mm off at 0.14 mm where the simpler one refuses (seed 0, cell 115): kept out until the edge's sigma knows",
)
def test_edge_fit_searching_below_its_window_finds_the_edge_inside() -> None:
    """Candidate edges so far below the window that nothing of the model is left in it have likelihood -inf (not
    the log of a negative mass: numpy's RuntimeWarning on every run of a part with such a face); the edge inside
    the window is still found."""
    rng = np.random.default_rng(5)
    s = rng.uniform(-0.03, 0.002, 3000) + 0.0003 * rng.standard_normal(3000)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        f = _extent.edge_fit(s, -0.01, 0.01, -0.03, 0.008)
    assert f.ok and abs(f.b - 0.002) < 3.0 * f.se + 1e-4


def test_line_box_span() -> None:
    box = Box(make_pose(rot_z(np.radians(90.0)), (1.0, 0.0, 0.0)), np.array([2.0, 4.0, 6.0]))
    s_in, s_out = _lines.line_box_span(np.array([1.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]), box)
    assert np.isclose(s_in, -2.0) and np.isclose(s_out, 2.0)  # the box's y (4 m) lies along R's x
    assert _lines.line_box_span(np.array([1.0, 5.0, 0.0]), np.array([1.0, 0.0, 0.0]), box)[0] == np.inf


def test_ransac_default_is_the_papers_voxel_cloud_three_runs_and_deterministic(scenes: dict) -> None:
    scene, truth = scenes["axis-aligned"]
    voxel = SeamScene(voxel_cloud(scene.dense, 0.01), scene.dense, scene.weldmap, scene.joints, scene.table_z)
    seam = voxel.weldmap.seam(TOP)
    loc = RansacLocator()
    assert loc.options.cloud == "voxel" and loc.options.runs == 3
    e1 = loc.locate(voxel, seam, np.random.default_rng(3))
    e2 = loc.locate(voxel, seam, np.random.default_rng(3))
    assert e1.status is SeamStatus.FOUND, e1.reason
    assert e1.reason.split(",")[0].endswith("/3 runs")
    assert np.array_equal(e1.p_start, e2.p_start) and np.array_equal(e1.p_end, e2.p_end)
    lat, along = errors(e1.p_start, e1.p_end, truth[TOP])
    assert lat < 0.006 and along < 0.04, (lat, along)  # 1 cm voxels: the ends are the weak part
    # The dense variant reads scene.dense, not the voxel cloud.
    dense = RansacLocator(RansacOptions(cloud="dense")).locate(voxel, seam, np.random.default_rng(3))
    assert dense.status is SeamStatus.FOUND, dense.reason
    lat_d, _ = errors(dense.p_start, dense.p_end, truth[TOP])
    assert lat_d < 0.004, lat_d
