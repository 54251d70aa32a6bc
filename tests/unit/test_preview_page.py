"""The page of a run (cell.preview.page) and the cell around the part (cell.pipeline.scene_view), on the tiny T
joint of test_preview and the real KR 5 arc: a DOM check of the figure data the page embeds."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from page_dom import read
from test_preview import SEAMS, WELDMAP, surface_cloud, torch_along

from cell import scenario as sc
from cell.geometry import FloatArray, make_pose
from cell.motion.robot import RobotModel
from cell.pipeline import Detection, WeldRun
from cell.pipeline.scene_view import cameras_R, cell_view, urdf_shapes
from cell.preview.cell3d import view_points
from cell.preview.html import figure_3d
from cell.preview.page import write_page
from cell.preview.results import results_rows
from cell.station.arm import robot_urdf
from cell.station.ports import Arm
from cell.types import (
    Box,
    CellView,
    MetricsSummary,
    SeamEstimate,
    SeamMetrics,
    SeamOutcome,
    SeamStatus,
    SeamWeld,
    ShapeKind,
    WeldReason,
)
from cell.types.curve_estimate import CurveEstimate

SCENARIO = sc.load("fence1")


@pytest.fixture(scope="module")
def arm() -> Arm:
    model = RobotModel.from_urdf(robot_urdf(SCENARIO))
    q = np.radians(np.asarray(SCENARIO.robot.home_deg, dtype=float))
    return Arm(model, q, q)


def test_urdf_shapes_and_camera_frusta() -> None:
    shapes = urdf_shapes(robot_urdf(SCENARIO))
    links = {s.link for s in shapes}
    assert {"base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "torch"} <= links
    base = next(s for s in shapes if s.link == "base_link")
    # the base as robots/build_kr5_arc.py draws it: 340 x 340 x 220 mm, standing on the mounting face
    assert base.kind is ShapeKind.BOX and np.allclose(base.size, [0.34, 0.34, 0.22]) and base.X_LS[2, 3] == 0.11
    assert {s.kind for s in shapes} == {ShapeKind.BOX, ShapeKind.CYLINDER}
    assert any(s.rgba[:3] == (1.0, 0.4, 0.0) for s in shapes)  # the URDF's named material "orange"
    cams = {c.name: c for c in cameras_R(SCENARIO)}
    assert set(cams) == set(SCENARIO.cameras)
    for name, c in cams.items():
        spec = SCENARIO.cameras[name]
        f = c.frustum()
        eye_R = np.asarray(spec.eye_m) - SCENARIO.X_WR[:3, 3]  # X_WR is a translation in fence1
        assert np.allclose(f[0], eye_R)
        ray_l, ray_r = f[1] - f[0], f[2] - f[0]  # top-left and top-right: the horizontal field of view
        x = c.X_RC[:3, 0]
        across = math.atan2(ray_r @ x, ray_r @ c.X_RC[:3, 2]) - math.atan2(ray_l @ x, ray_l @ c.X_RC[:3, 2])
        assert math.degrees(across) == pytest.approx(spec.hfov_deg, abs=0.1)
        assert np.mean(f[1:], axis=0) @ c.X_RC[:3, 2] - f[0] @ c.X_RC[:3, 2] == pytest.approx(c.range_m)


def test_cell_view_poses_are_the_arms_forward_kinematics(arm: Arm) -> None:
    view = cell_view(SCENARIO, arm, None)
    assert view.table is not None and view.table.center[2] == pytest.approx(-0.05)  # top at the base's height
    assert len(view.poses) == 1 and view.poses[0].label == "scan pose"
    assert np.allclose(view.poses[0].X_RL["torch"], arm.model.fk(arm.q_scan, "torch"))
    assert set(view.poses[0].X_RL) == set(view.links)
    assert view.motion is None and view.limits == arm.model.limits  # no plan, no motion; the limits as values


def test_3d_view_draws_the_cell_and_frames_the_part(arm: Arm) -> None:
    view = cell_view(SCENARIO, arm, None)
    # The tiny T joint stands about a metre in front of the robot, as fence1's part does.
    shift = make_pose(p=[0.0, 1.0, 1.0])
    weldmap = WELDMAP.transformed(shift, "R")
    cloud = surface_cloud(np.random.default_rng(3), 800) + shift[:3, 3]
    fig = figure_3d(cloud, weldmap, [], {}, {}, view=view).to_dict()
    names = [t.get("name") for t in fig["data"]]
    assert "table" in names and "camera cam_left" in names and "camera eye_in_hand" in names
    assert [n for n in names if str(n).startswith("robot ")] == [f"robot {link}" for link in view.links]
    scene = fig["layout"]["scene"]
    # plotly's camera lives in the scene box: each axis spans its aspect ratio, centred on 0 (range mid-point).
    lo = np.array([scene[f"{a}axis"]["range"][0] for a in "xyz"])
    hi = np.array([scene[f"{a}axis"]["range"][1] for a in "xyz"])
    aspect = np.array([scene["aspectratio"][a] for a in "xyz"])

    def to_scene(p_mm: FloatArray) -> FloatArray:
        return np.asarray((p_mm - (lo + hi) / 2.0) / (hi - lo) * aspect)

    eye = np.array([scene["camera"]["eye"][a] for a in "xyz"])
    centre = np.array([scene["camera"]["center"][a] for a in "xyz"])
    corners = np.vstack([p.vertices() for p in weldmap.parts]) * 1000.0
    axis = (centre - eye) / np.linalg.norm(centre - eye)
    for p in to_scene(corners):  # every corner of the part inside the vertical field of view (45 deg)
        ray = (p - eye) / np.linalg.norm(p - eye)
        assert math.degrees(math.acos(np.clip(ray @ axis, -1, 1))) < 22.5
    # ... and the part fills a good share of it (not a speck in a view of the whole cell).
    rays = [(p - eye) / np.linalg.norm(p - eye) for p in to_scene(corners)]
    assert max(math.degrees(math.acos(np.clip(r @ axis, -1, 1))) for r in rays) > 10.0
    inside = to_scene(np.vstack([view_points(view), cloud * 1000.0]))  # nothing drawn outside the axes
    assert np.all(np.abs(inside) <= aspect / 2 + 1e-9)
    # Without the cell (a run that carries no view) the camera is framed to the part too.
    bare = figure_3d(cloud, weldmap, [], {}, {}).to_dict()["layout"]["scene"]
    lo2 = np.array([bare[f"{a}axis"]["range"][0] for a in "xyz"])
    hi2 = np.array([bare[f"{a}axis"]["range"][1] for a in "xyz"])
    aspect2 = np.array([bare["aspectratio"][a] for a in "xyz"])
    centre2 = np.array([bare["camera"]["center"][a] for a in "xyz"]) / aspect2 * (hi2 - lo2) + (lo2 + hi2) / 2.0
    assert np.allclose(centre2, (corners.min(axis=0) + corners.max(axis=0)) / 2.0, atol=1e-6)


def tiny_run() -> WeldRun:
    """A preview-like run of the tiny T joint: one seam found and planned, one not found, one not visible."""
    front = SEAMS[0]
    est = (
        SeamEstimate("S_front", SeamStatus.FOUND, "", front.p_start, front.p_end, 0.9, sigma_m=0.00012),
        SeamEstimate("S_back", SeamStatus.NOT_FOUND, "no edge in the cloud"),
        SeamEstimate("S_left", SeamStatus.NOT_VISIBLE, "against the table"),
    )
    metrics = {"S_front": SeamMetrics("S_front", SeamStatus.FOUND, 0.31, 0.4, 0.2, 1.0)}
    summary = MetricsSummary(3, 2, 1, 0.31, 0.31, 0.4, 0.2, 1.0)
    truths = {s.id: (s.p_start, s.p_end) for s in SEAMS[:2]}
    det = Detection(SCENARIO, "ours", WELDMAP, est, truths, metrics, summary)
    welds = (
        SeamWeld("S_front", True, False, "planned (preview)", code=WeldReason.PREVIEW),
        SeamWeld("S_back", False, False, "not located", code=WeldReason.NOT_LOCATED),
        SeamWeld("S_left", False, False, "flip the part", code=WeldReason.NOT_VISIBLE),
    )
    table = Box(make_pose(p=[0.0, 0.0, -1.07]), np.array([1.0, 0.6, 0.1]))
    view = CellView(table=table, cameras=cameras_R(SCENARIO))
    X = torch_along(front)
    return WeldRun(detection=det, seams=welds, torch_paths={"S_front": X}, view=view)


def test_page_has_results_table_and_cell_figure(tmp_path: Path) -> None:
    run = tiny_run()
    out = write_page(run, tmp_path / "cell.html", title="tiny T joint")
    text = out.read_text(encoding="utf-8")
    assert 'src="https://' not in text and text.count("Plotly.newPlot") >= 1  # plotly.js inline, offline
    figs, rows = read(out)
    assert set(figs) == {"cell3d"}  # no plan: no joint plots
    names = [t.get("name") for t in figs["cell3d"]["data"]]
    assert {"table", "camera cam_right", "seams found", "seams not found", "seams not visible"} <= set(names)
    assert [r["seam"] for r in rows] == ["S_front", "S_back", "S_left"]
    assert [r["status"] for r in rows] == ["found", "not_found", "not_visible"]
    front = dict(zip(["seam", "status", "sigma", "error", "weld", "work", "travel"], rows[0]["cells"], strict=True))
    assert front["sigma"] == "0.12" and front["error"] == "0.31" and front["weld"] == "planned"
    assert rows[1]["cells"][4] == "not located" and rows[2]["cells"][4] == "not visible"
    hover = next(t for t in figs["cell3d"]["data"] if t.get("name") == "seams found")["text"][0]
    assert "S_front" in hover and "sigma 0.12 mm" in hover


def test_results_rows_give_torch_angles() -> None:
    run = tiny_run()
    o = SeamOutcome("S_front", True, work_angle=math.radians(45.0), travel_angle=math.radians(-10.0))
    rec = run.records()[0]
    row = results_rows([replace(rec, outcome=o)])[0]
    assert row["work angle [deg]"] == "45.0" and row["travel angle [deg]"] == "-10.0"


def test_seam_labels_do_not_overlap() -> None:
    from cell.preview.figures import new_figure
    from cell.preview.labels import place_labels

    fig = new_figure(6.0, 4.0)
    ax = fig.add_subplot()
    ax.set_xlim(0.0, 100.0)
    ax.set_ylim(0.0, 100.0)
    labels = [("1,3,4", (50.0, 50.0)), ("2", (51.0, 50.0)), ("5,7,8", (50.0, 51.0)), ("6", (52.0, 49.0))]
    anns = place_labels(fig, ax, labels)
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    boxes = [a.get_window_extent(renderer) for a in anns]
    assert len(boxes) == 4
    assert not any(boxes[i].overlaps(boxes[j]) for i in range(4) for j in range(i + 1, 4))


def test_overview_legend_lists_only_what_is_drawn(tmp_path: Path) -> None:
    from test_preview import colour_fraction

    from cell.preview import STATUS_COLOURS, SeamView, render_overview

    found = [SeamView(s.id, "found", s.p_start, s.p_end) for s in SEAMS]
    cloud = surface_cloud(np.random.default_rng(4), 500)
    top = render_overview(cloud, WELDMAP, found, {}, {}, tmp_path)[0]
    assert colour_fraction(top, STATUS_COLOURS["found"]) > 1e-4
    for status in ("not_found", "not_visible", "occluded"):  # no seam of theirs: no legend entry in their colour
        assert colour_fraction(top, STATUS_COLOURS[status]) == 0.0, status


def test_scan_pose_holds_the_eye_in_hand_camera_where_its_frustum_starts() -> None:
    from cell.pipeline.geometry import robot_arm

    arm = robot_arm(SCENARIO)  # q_scan by IK on the camera's viewpoint
    view = cell_view(SCENARIO, arm, None)
    (cam,) = (c for c in view.cameras if c.mount == "eye_in_hand")
    X_R_link = view.poses[0].X_RL["camera_link"]  # the drawn camera body at the scan pose
    assert np.linalg.norm(X_R_link[:3, 3] - cam.frustum()[0]) < 0.01  # measured 3e-6 m (the optical origin)


def test_joint_plots_shade_each_weld_on_every_row_and_draw_only_the_limits_in_view() -> None:
    """Two welds shaded on each joint's own axes and labelled once on the top row; A1 runs near its upper limit
    (drawn, dashed), A2 far from both (none drawn)."""
    from types import SimpleNamespace

    from cell.preview.page import joint_figure
    from cell.types import JointLimits

    t = np.linspace(0.0, 10.0, 101)
    q = np.zeros((len(t), 2))
    q[:, 0] = 2.97 + 0.02 * np.sin(t)  # its +3 rad limit within the axis's 15 % margin over the motion
    ones = np.ones(2)
    limits = JointLimits(("A1", "A2"), np.full(2, -3.0), np.full(2, 3.0), ones, ones, ones)
    bands = [(1.0, 2.5, "S1"), (6.0, 7.0, "S2")]
    layout = joint_figure(SimpleNamespace(times=t, q=q), limits, bands).to_plotly_json()["layout"]
    rects = [(s["xref"], s["yref"], s["x0"], s["x1"]) for s in layout["shapes"] if s["type"] == "rect"]
    assert rects == [(x, f"{y} domain", a, b) for x, y in (("x", "y"), ("x2", "y2")) for a, b, _ in bands]
    lines = [(s["yref"], s["y0"]) for s in layout["shapes"] if s["type"] == "line"]
    assert lines == [("y", pytest.approx(math.degrees(3.0)))]
    labels = [(a["text"], a["x"], a["xref"]) for a in layout["annotations"] if a["text"] in ("S1", "S2")]
    assert labels == [("S1", 1.75, "x"), ("S2", 6.5, "x")]


def circle(cid: str, x0: float) -> CurveEstimate:
    """A located 50 mm circle about z through (x0, 0, 0) in R, 300 samples."""
    t = np.linspace(0.0, 2 * np.pi, 300, endpoint=False)
    p = np.column_stack([x0 + 0.05 * np.cos(t), 0.05 * np.sin(t), np.zeros_like(t)])
    up, out = np.tile([0.0, 0.0, 1.0], (300, 1)), np.column_stack([np.cos(t), np.sin(t), 0 * t])
    return CurveEstimate(cid, SeamStatus.FOUND, p_RS=p, n_abutting_R=out, n_receiving_R=up, closed=True,
                         sigma_m=np.full(300, 1e-4))  # fmt: skip


def test_the_page_marks_the_stretches_left_for_a_manual_weld_on_their_located_curve(tmp_path: Path) -> None:
    """A curve welded in part is drawn with its remainder dashed over it, each stretch from its start to its end
    along the located curve (one passing the closed curve's start), hovering the console's words; a curve not
    welded goes in its own trace; with the map's pose, the stretch's ends on the drawing."""
    from cell.export.reports.curve_report import remainder_entry, remainder_words
    from cell.geometry import invert
    from cell.preview.curves3d import curve_traces
    from cell.types.plan import PlanReason, Remainder

    part, refused = circle("TUBE>PLATE:circle", 0.0), circle("POST>PLATE:circle", 0.3)
    L = part.length_m
    rest = (Remainder(0.25 * L, 0.5 * L, PlanReason.COLLISION, "torch vs GUSSET_1"),
            Remainder(0.9 * L, 1.1 * L, PlanReason.IK_FAILED, "no torch setting holds it"))  # fmt: skip
    welds = {
        part.id: SeamWeld(part.id, True, False, "welded in part", code=WeldReason.PARTIAL, share=0.55, remainder=rest),
        refused.id: SeamWeld(refused.id, False, False, "no IK", code=WeldReason.NOT_PLANNED),
    }
    run = tiny_run()
    run = replace(run, detection=replace(run.detection, curve_estimates=(part, refused), curve_welds=welds))
    figs, _ = read(write_page(run, tmp_path / "cell.html"))
    data = {t.get("name"): t for t in figs["cell3d"]["data"]}
    assert data["curves welded in part"]["text"][0].startswith(part.id)
    assert data["curves not welded"]["text"][0] == f"{refused.id}<br>not welded: no IK"
    manual = data["manual weld"]
    xyz = np.array([manual[k] for k in "xyz"], dtype=float).T  # None breaks -> nan
    pieces = np.split(xyz, np.flatnonzero(np.isnan(xyz[:, 0])))
    pieces = [p[~np.isnan(p[:, 0])] for p in pieces if (~np.isnan(p[:, 0])).any()]
    assert len(pieces) == 2
    for p, r in zip(pieces, rest, strict=True):
        ends = part.points_at([r.from_m, r.to_m]) * 1000.0
        assert np.allclose(p[[0, -1]], ends, atol=0.06)
        assert np.allclose(np.hypot(p[:, 0], p[:, 1]), 50.0, atol=0.1)  # along the curve, not its chord
        assert np.linalg.norm(np.diff(p, axis=0), axis=1).sum() == pytest.approx(r.length_m * 1000.0, rel=0.01)
    words = remainder_words(remainder_entry(rest[0]))  # the console's line for it
    assert manual["text"][0] == f"{part.id}<br>manual weld {words}" and words.startswith("78-157 mm along it")
    planned = {part.id: replace(welds[part.id], code=WeldReason.PREVIEW)}  # a preview: planned in part
    (in_part, _) = curve_traces((part,), planned)
    assert in_part["name"] == "curves planned in part" and "planned in part (55%)" in in_part["text"][0]
    stopped = {part.id: replace(welds[part.id], code=WeldReason.NOT_EXECUTED)}  # the gate stopped the job
    assert [t["name"] for t in curve_traces((part,), stopped)] == ["curves not welded"]
    X_RM = make_pose(p=[0.2, 0.0, 0.1])  # the drawing 0.2 m behind and 0.1 m below R: the ends moved by it
    (_, _, mark) = curve_traces((part, refused), welds, invert(X_RM))
    a = np.round(part.points_at([rest[0].from_m])[0] * 1000.0 - [200.0, 0.0, 100.0]).astype(int)
    assert f"from ({a[0]}, {a[1]}, {a[2]})" in mark["text"][0] and mark["text"][0].endswith("torch vs GUSSET_1")


def test_a_positioner_job_has_a_page_with_every_seam_and_its_curves_in_part(tmp_path: Path) -> None:
    """A positioner job's page: the straight seams' welds from its poses, a seam no pose holds with why, and its
    curve welded in part with its stretch marked (no robot, no joint plots: the part moves between poses)."""
    from cell.pipeline.positioned.run import GroupRun, PositionerRun
    from cell.positioner.poses import PositionerPose
    from cell.types.plan import PlanReason, Remainder

    base = tiny_run().detection
    tube = circle("TUBE>PLATE:circle", 0.3)
    rest = (Remainder(0.1, 0.15, PlanReason.IK_FAILED, "joint_a3 at its limit"),)
    seams = (
        SeamWeld("S_front", True, True, ""),
        SeamWeld(tube.id, True, False, "welded in part", code=WeldReason.PARTIAL, share=0.84, remainder=rest),
    )
    group = GroupRun(PositionerPose(0.0, 0.0, (), {}), 0.0, None, None, None, seams, 0.0)
    run = PositionerRun(replace(base, curve_estimates=(tube,)), (group,), unheld={"S_left": "beyond the tilt"},
                        unheld_codes={"S_left": WeldReason.NOT_PLANNED})  # fmt: skip
    page = write_page(run.as_weld_run(), tmp_path / "cell.html")
    figs, rows = read(page)
    assert set(figs) == {"cell3d"}
    cells = {r["seam"]: r["cells"][4] for r in rows}
    assert cells["S_front"] == "welded" and cells["S_left"] == "not planned" and tube.id in cells
    assert "beyond the tilt" in page.read_text(encoding="utf-8")  # why no pose holds it
    data = {t.get("name"): t for t in figs["cell3d"]["data"]}
    assert "curves welded in part" in data and data["manual weld"]["text"][0].startswith(tube.id)
