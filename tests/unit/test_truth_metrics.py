"""Seam geometry (joints, weld faces), ground truth, visibility and metrics, on fences built from boxes by
hand."""

from __future__ import annotations

import numpy as np
import pytest

from cell.errors import MapError
from cell.geometry import invert, make_pose, rot_z, transform_points
from cell.seams.joint import fillet_bisector, find_joints, weld_faces
from cell.seams.metrics import evaluate, seam_metrics, segment_errors, summarise
from cell.seams.truth import true_seams
from cell.seams.visibility import UNDERSIDE_REASON, visibility
from cell.types import Box, Joint, MapSeam, Part, SeamEstimate, SeamStatus, WeldMap

MM = 0.001


def box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> Box:
    """An axis-aligned box from its corners [mm]."""
    lo_m, hi_m = np.asarray(lo) * MM, np.asarray(hi) * MM
    return Box(make_pose(p=(lo_m + hi_m) / 2.0), hi_m - lo_m)


def seam(sid: str, a: tuple[float, float, float], b: tuple[float, float, float]) -> MapSeam:
    return MapSeam(sid, np.asarray(a) * MM, np.asarray(b) * MM)


TOP = Part("TOP_RAIL", box((0, 700, 0), (1400, 800, 100)))
POST_L = Part("POST_L", box((200, 0, 0), (280, 699, 80)))
POST_R = Part("POST_R", box((1120, 0, 0), (1200, 699, 80)))
BOTTOM = Part("BOTTOM_RAIL", box((281, 250, 0), (1119, 310, 60)))

POST_L_SEAMS = (
    seam("POST_L>TOP_RAIL:+z", (200, 700, 80), (280, 700, 80)),
    seam("POST_L>TOP_RAIL:-z", (200, 700, 0), (280, 700, 0)),
    seam("POST_L>TOP_RAIL:-x", (200, 700, 0), (200, 700, 80)),
    seam("POST_L>TOP_RAIL:+x", (280, 700, 80), (280, 700, 0)),  # drawn top-down on purpose
)


def fence4() -> WeldMap:
    """The paper's fence no.1: four parts, four junctions, 16 seams."""
    seams = list(POST_L_SEAMS)
    seams += [
        seam("POST_R>TOP_RAIL:+z", (1120, 700, 80), (1200, 700, 80)),
        seam("POST_R>TOP_RAIL:-z", (1120, 700, 0), (1200, 700, 0)),
        seam("POST_R>TOP_RAIL:-x", (1120, 700, 0), (1120, 700, 80)),
        seam("POST_R>TOP_RAIL:+x", (1200, 700, 0), (1200, 700, 80)),
    ]
    for x, post in ((280, "POST_L"), (1120, "POST_R")):
        seams += [
            seam(f"BOTTOM_RAIL>{post}:+z", (x, 250, 60), (x, 310, 60)),
            seam(f"BOTTOM_RAIL>{post}:-z", (x, 250, 0), (x, 310, 0)),
            seam(f"BOTTOM_RAIL>{post}:-y", (x, 250, 0), (x, 250, 60)),
            seam(f"BOTTOM_RAIL>{post}:+y", (x, 310, 0), (x, 310, 60)),
        ]
    return WeldMap((TOP, POST_L, POST_R, BOTTOM), tuple(seams), "mm", "test")


def fence2parts() -> WeldMap:
    return WeldMap((TOP, POST_L), POST_L_SEAMS, "mm", "test")


# --- joints
# ---------------------------------------------------------------------------------------------------


def test_find_joints_two_parts() -> None:
    joints = find_joints(fence2parts())
    assert set(joints) == {s.id for s in POST_L_SEAMS}
    for sid, face in (("+z", "+z"), ("-z", "-z"), ("-x", "-x"), ("+x", "+x")):
        j = joints[f"POST_L>TOP_RAIL:{sid}"]
        assert (j.abutting, j.receiving) == ("POST_L", "TOP_RAIL")
        assert (j.face_abutting, j.face_receiving, j.end_face) == (face, "-y", "+y")


def test_find_joints_four_parts_matches_the_ids() -> None:
    """The ids say A>B:face; find_joints never reads them, so they are an independent check."""
    joints = find_joints(fence4())
    assert len(joints) == 16
    for sid, j in joints.items():
        parts, face = sid.split(":")
        a, b = parts.split(">")
        assert (j.seam_id, j.abutting, j.receiving, j.face_abutting) == (sid, a, b, face)
        if b == "TOP_RAIL":
            assert (j.face_receiving, j.end_face) == ("-y", "+y")
        else:  # the bottom rail meets POST_L's +x face with its -x end, POST_R's -x face with its +x end
            expected = ("+x", "-x") if b == "POST_L" else ("-x", "+x")
            assert (j.face_receiving, j.end_face) == expected


def test_find_joints_in_a_rotated_frame() -> None:
    """Geometry, not axis names: the same fence yawed and moved gives the same joints."""
    X = make_pose(rot_z(0.7), [0.3, -1.2, 0.05])
    assert find_joints(fence4().transformed(X, "R")) == find_joints(fence4())


def test_seam_floating_in_air_is_a_map_error() -> None:
    bad = seam("POST_L>TOP_RAIL:+z", (200, 720, 80), (280, 720, 80))  # 20 mm behind the rail's face
    with pytest.raises(MapError, match="POST_L>TOP_RAIL:\\+z"):
        find_joints(WeldMap((TOP, POST_L), (bad,), "mm", "test"))
    air = seam("AIR", (500, 400, 300), (600, 400, 300))
    with pytest.raises(MapError, match="'AIR' does not sit on two parts"):
        find_joints(WeldMap((TOP, POST_L), (air,), "mm", "test"))


def test_seam_on_one_part_only_is_a_map_error() -> None:
    lonely = seam("EDGE", (0, 700, 100), (100, 700, 100))  # an edge of the top rail, nothing abuts there
    with pytest.raises(MapError, match="'EDGE'"):
        find_joints(WeldMap((TOP, POST_L), (lonely,), "mm", "test"))


def test_weld_faces_and_fillet_bisector() -> None:
    wm = fence2parts()
    j = find_joints(wm)["POST_L>TOP_RAIL:+z"]
    n_a, d_a, n_b, d_b = weld_faces(wm, j)
    np.testing.assert_allclose(n_a, [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(n_b, [0, -1, 0], atol=1e-12)
    assert d_a == pytest.approx(0.080) and d_b == pytest.approx(-0.700)
    np.testing.assert_allclose(fillet_bisector(wm, j), np.array([0, -1, 1]) / np.sqrt(2), atol=1e-12)
    j = find_joints(wm)["POST_L>TOP_RAIL:-x"]
    np.testing.assert_allclose(fillet_bisector(wm, j), np.array([-1, -1, 0]) / np.sqrt(2), atol=1e-12)


# --- truth
# ----------------------------------------------------------------------------------------------------

X_WR = make_pose(rot_z(0.2), [0.15, -1.1, 1.9])
X_WM = make_pose(rot_z(-0.1), [-0.55, -0.40, 0.90])


def _truth(parts_W: list[Part]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    design = fence4()
    return true_seams(design, find_joints(design), parts_W, X_WR)


def _built(**changes: Box) -> list[Part]:
    """The fence in the world, with some parts' boxes (given in M) replaced."""
    return [Part(p.name, changes.get(p.name, p.box).transformed(X_WM)) for p in fence4().parts]


def _map_in_R(sid: str) -> tuple[np.ndarray, np.ndarray]:
    s = fence4().seam(sid).transformed(invert(X_WR) @ X_WM)
    return np.asarray(s.p_start), np.asarray(s.p_end)


def test_truth_without_deviation_is_the_map_seam_in_R() -> None:
    truth = _truth(_built())
    assert len(truth) == 16
    for sid, (t0, t1) in truth.items():
        m0, m1 = _map_in_R(sid)
        np.testing.assert_allclose(t0, m0, atol=1e-9, err_msg=sid)
        np.testing.assert_allclose(t1, m1, atol=1e-9, err_msg=sid)  # also keeps the map's start/end order


def test_truth_follows_a_translated_part() -> None:
    moved = box((196, 0, 0), (276, 699.5, 80))  # POST_L 4 mm towards -x, its end 0.5 mm nearer the rail
    truth = _truth(_built(POST_L=moved))
    shift_R = (invert(X_WR) @ X_WM)[:3, :3] @ np.array([-0.004, 0.0, 0.0])
    for sid in ("POST_L>TOP_RAIL:+z", "POST_L>TOP_RAIL:-x", "POST_L>TOP_RAIL:+x"):
        m0, m1 = _map_in_R(sid)
        np.testing.assert_allclose(truth[sid][0], m0 + shift_R, atol=1e-9)  # still on the rail's face
        np.testing.assert_allclose(truth[sid][1], m1 + shift_R, atol=1e-9)
    # The bottom rail's seams move with POST_L's +x face: 4 mm, onto the receiving face across a 5 mm gap.
    m0, _ = _map_in_R("BOTTOM_RAIL>POST_L:+z")
    np.testing.assert_allclose(truth["BOTTOM_RAIL>POST_L:+z"][0], m0 + shift_R, atol=1e-9)


def test_truth_follows_a_lengthened_and_thickened_part() -> None:
    # The bottom rail 3 mm thicker (y) and 2 mm taller (z): the seams stay on the posts' faces, at its new
    # edges.
    rail = box((281, 248.5, 0), (1119, 311.5, 62))
    truth = _truth(_built(BOTTOM_RAIL=rail))
    X_RM = invert(X_WR) @ X_WM
    t0, t1 = truth["BOTTOM_RAIL>POST_L:+z"]
    np.testing.assert_allclose(t0, transform_points(X_RM, np.array([0.280, 0.2485, 0.062])), atol=1e-9)
    np.testing.assert_allclose(t1, transform_points(X_RM, np.array([0.280, 0.3115, 0.062])), atol=1e-9)
    longer = box((275, 250, 0), (1125, 310, 60))  # 6 mm longer at each end (into the posts): still on their faces
    t0, _ = _truth(_built(BOTTOM_RAIL=longer))["BOTTOM_RAIL>POST_R:-y"]
    np.testing.assert_allclose(t0, transform_points(X_RM, np.array([1.120, 0.250, 0.0])), atol=1e-9)


def test_truth_projects_along_a_tilted_abutting_part() -> None:
    """A post yawed 1 deg about its centre: the seam stays on both weld-face planes (the fillet corner)."""
    yaw = np.radians(1.0)
    X = make_pose(rot_z(yaw), [0.240, 0.3495, 0.040])
    tilted = Box(X, np.array([0.080, 0.699, 0.080]))
    truth = _truth(_built(POST_L=tilted))
    wm_R = WeldMap(tuple(_built(POST_L=tilted)), (), "mm", "t", "W").transformed(invert(X_WR), "R")
    for sid in ("POST_L>TOP_RAIL:+z", "POST_L>TOP_RAIL:-x"):
        j = find_joints(fence4())[sid]
        n_a, d_a, n_b, d_b = weld_faces(wm_R, j)
        for p in truth[sid]:
            assert abs(n_a @ p - d_a) < 1e-9 and abs(n_b @ p - d_b) < 1e-9


def test_truth_needs_every_part() -> None:
    with pytest.raises(MapError, match="POST_R"):
        _truth([p for p in _built() if p.name != "POST_R"])


# --- visibility
# -----------------------------------------------------------------------------------------------


def test_underside_seams_are_not_visible() -> None:
    X_RM = invert(X_WR) @ X_WM
    wm_R = fence4().transformed(X_RM, "R")
    table_z = float(transform_points(X_RM, np.zeros(3))[2])
    joints = find_joints(wm_R)
    for sid, j in joints.items():
        visible, reason = visibility(wm_R, j, table_z)
        if sid.endswith(":-z"):
            assert (visible, reason) == (False, UNDERSIDE_REASON)
        else:
            assert (visible, reason) == (True, "")
    # Lifted 20 mm off the table (on a jig), the underside seams can be seen.
    j = joints["POST_L>TOP_RAIL:-z"]
    assert visibility(wm_R, j, table_z - 0.020)[0]


def test_visibility_uses_the_real_normal_not_the_face_name() -> None:
    """A post rolled 180 deg about its length: its box '+z' face now lies on the table."""
    flip = make_pose(np.diag([1.0, -1.0, -1.0]), [0.240, 0.3495, 0.040])
    post = Part("POST_L", Box(flip, np.array([0.080, 0.699, 0.080])))
    wm = WeldMap((TOP, post), POST_L_SEAMS, "mm", "test")
    joints = find_joints(wm)
    j = joints["POST_L>TOP_RAIL:-z"]  # the id is the drawing's name; the joint has the box face
    assert j.face_abutting == "+z"
    assert visibility(wm, j, 0.0) == (False, UNDERSIDE_REASON)
    assert visibility(wm, joints["POST_L>TOP_RAIL:+z"], 0.0) == (True, "")


# --- metrics
# --------------------------------------------------------------------------------------------------

T0, T1 = np.array([1.0, 2.0, 0.5]), np.array([1.0, 2.06, 0.5])  # a true seam along y [m]


def _est(p0: np.ndarray, p1: np.ndarray, sid: str = "s", t: float = 0.002) -> SeamEstimate:
    return SeamEstimate(sid, SeamStatus.FOUND, "", p0, p1, 1.0, t)


def test_metrics_known_offsets() -> None:
    d = np.array([0.001, -0.002, 0.003])  # dx 1 mm, dy -2 mm, dz 3 mm
    m = seam_metrics(_est(T0 + d, T1 + d), T0, T1)
    assert m.paper_me_mm == pytest.approx(3.0)
    assert m.endpoint_mm == pytest.approx(np.sqrt(14.0))
    assert m.lateral_mm == pytest.approx(np.hypot(1.0, 3.0))  # the dy part runs along the seam
    assert not m.swapped and m.time_ms == pytest.approx(2.0)


def test_metrics_different_errors_at_each_end() -> None:
    m = seam_metrics(_est(T0 + np.array([0.002, 0, 0]), T1 + np.array([0, 0.004, 0])), T0, T1)
    assert m.paper_me_mm == pytest.approx(3.0)
    assert m.endpoint_mm == pytest.approx(3.0)
    assert m.lateral_mm == pytest.approx(2.0)  # the end is off along the line: the start sets the lateral error


def test_metrics_swapped_ends_are_matched() -> None:
    m = seam_metrics(_est(T1 + np.array([0.001, 0, 0]), T0 + np.array([0.001, 0, 0])), T0, T1)
    assert m.swapped
    assert m.paper_me_mm == pytest.approx(1.0) and m.lateral_mm == pytest.approx(1.0)


def test_metrics_lateral_offset_only() -> None:
    assert segment_errors(T0 + np.array([0, 0, -0.0015]), T1 + np.array([0, 0, -0.0015]), T0, T1) == pytest.approx(
        (0.0, 1.5, 1.5, False)
    )


def test_summary() -> None:
    ests = [
        _est(T0 + np.array([0.001, 0, 0]), T1 + np.array([0.001, 0, 0]), "a", 0.001),
        _est(T0 + np.array([0, 0.003, 0]), T1 + np.array([0, 0.003, 0]), "b", 0.003),
        SeamEstimate("c", SeamStatus.NOT_FOUND, "nothing there", time_s=0.005),
        SeamEstimate("d", SeamStatus.NOT_VISIBLE, UNDERSIDE_REASON),
    ]
    per = evaluate(ests, {k: (T0, T1) for k in "abcd"})
    assert set(per) == {"a", "b"}
    s = summarise(ests, per)
    assert (s.seams, s.visible, s.found) == (4, 3, 2)
    assert s.paper_me_mean_mm == pytest.approx(2.0)
    assert s.paper_me_p95_mm == pytest.approx(1.0 + 0.95 * 2.0)
    assert s.endpoint_mean_mm == pytest.approx(2.0)
    assert s.lateral_mean_mm == pytest.approx(0.5)
    assert s.time_ms_per_seam_median == pytest.approx(3.0)
    empty = summarise([ests[3]], {})
    assert empty.found == 0 and np.isnan(empty.paper_me_mean_mm)


def test_not_found_metrics_are_nan() -> None:
    m = seam_metrics(SeamEstimate("c", SeamStatus.NOT_FOUND, "x"), T0, T1)
    assert not m.found and np.isnan(m.paper_me_mm)


def test_joint_is_a_value() -> None:
    assert Joint("s", "A", "B", "+z", "-y", "+y") == Joint("s", "A", "B", "+z", "-y", "+y")
