"""fence1's Rerun recording (``cell weld fence1 --rerun FILE.rrd``), read back with rerun's own reader.

The session's weld of fence1 (``fence1_run``) is recorded once; the file is opened with
``rerun.chunk.RrdReader`` and its entities compared with the run's values: the cloud, the map's parts, the
seams by status, the cameras, the robot's links posed on the ``time`` timeline over the whole motion, the tool
path and the arc.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cell import pipeline
from cell.geometry import invert, transform_points
from cell.pipeline.scene_view import cell_view
from cell.types import SeamStatus

rerun = pytest.importorskip("rerun")
import pyarrow as pa  # noqa: E402  (rerun's own dependency)
from rerun.chunk import RrdReader  # noqa: E402

from cell.preview.rerun import APPLICATION_ID, RATE_HZ, record_run, recording_id  # noqa: E402


@pytest.fixture(scope="module")
def recorded(fence1_run: pipeline.WeldRun, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    """The recording of fence1's weld and its columns by entity path: ``{path: {column: [values per row]}}``
    (static and temporal rows of an entity concatenated in file order)."""
    path = record_run(fence1_run, tmp_path_factory.mktemp("rerun") / "fence1.rrd")
    cols: dict[str, dict[str, list[Any]]] = defaultdict(lambda: defaultdict(list))
    for chunk in RrdReader(path).store().stream():
        batch = chunk.to_record_batch()
        for name in batch.schema.names:
            col = batch.column(name)
            if pa.types.is_duration(col.type):  # a timeline: seconds
                cols[chunk.entity_path][name] += (col.cast(pa.int64()).to_numpy() / 1e9).tolist()
            elif not name.startswith("rerun."):
                cols[chunk.entity_path][name] += col.to_pylist()
    return path, cols


def test_the_file_is_one_recording_of_this_run(
    recorded: tuple[Path, dict[str, Any]], fence1_run: pipeline.WeldRun
) -> None:
    path, _ = recorded
    assert 1_000_000 < path.stat().st_size < 9_000_000  # measured 5.9 MB: 312k cloud points, 2758 poses
    (entry,) = RrdReader(path).recordings()
    assert entry.application_id == APPLICATION_ID
    assert entry.recording_id == recording_id(fence1_run) == recording_id(fence1_run)
    (layout,) = RrdReader(path).blueprints()  # the default layout: 3D cell, joints, arc, log
    assert layout.application_id == APPLICATION_ID


def test_cloud_map_seams_table_and_cameras(recorded: tuple[Path, dict[str, Any]], fence1_run: pipeline.WeldRun) -> None:
    _, cols = recorded
    det = fence1_run.detection
    assert det.scene is not None
    dense = np.asarray(det.scene.perceived.dense.points)
    (cloud,) = cols["/cell/cloud"]["Points3D:positions"]
    assert len(cloud) == len(dense) > 100_000
    np.testing.assert_allclose(np.asarray(cloud)[::997], dense[::997], atol=1e-6)  # stored as float32
    (labels,) = cols["/cell/map/parts"]["Boxes3D:labels"]
    assert labels == [p.name for p in det.weldmap_R.parts]
    (centres,) = cols["/cell/map/parts"]["Boxes3D:centers"]
    np.testing.assert_allclose(centres, [p.box.X_AB[:3, 3] for p in det.weldmap_R.parts], atol=1e-6)
    by_status: dict[str, list[str]] = defaultdict(list)
    for e in det.estimates:
        by_status[str(e.status)].append(e.id)
    assert set(by_status) == {"found", "not_visible"}
    for status, ids in by_status.items():
        assert cols[f"/cell/seams/{status}"]["LineStrips3D:labels"] == [ids]
    found = {e.id: e for e in det.estimates if e.status is SeamStatus.FOUND}
    (strips,) = cols["/cell/seams/found"]["LineStrips3D:strips"]
    for sid, strip in zip(by_status["found"], strips, strict=True):
        np.testing.assert_allclose(strip, [found[sid].p_start, found[sid].p_end], atol=1e-6)
    assert len(cols["/cell/seams/truth"]["LineStrips3D:labels"][0]) == len(det.truths)
    assert cols["/cell/table"]["Boxes3D:centers"]
    assert fence1_run.view is not None
    for cam in fence1_run.view.cameras:
        c = cols[f"/cell/cameras/{cam.name}"]
        assert c["Pinhole:resolution"][0][0] == [cam.intrinsics.width, cam.intrinsics.height]
        if cam.mount == "fixed":  # static; the eye-in-hand camera rides on the arm (next test)
            (X,) = c["Transform3D:translation"]
            np.testing.assert_allclose(X[0], cam.X_RC[:3, 3], atol=1e-6)


def test_robot_links_move_on_the_timeline_over_the_whole_motion(
    recorded: tuple[Path, dict[str, Any]], fence1_run: pipeline.WeldRun
) -> None:
    _, cols = recorded
    ex, view, arm = fence1_run.execution, fence1_run.view, fence1_run.arm
    assert ex is not None and view is not None and arm is not None
    for link in ("base_link", "link_1", "link_3", "link_6", "torch"):
        assert any(p.startswith(f"/cell/robot/{link}/") for p in cols), link  # its shapes
        c = cols[f"/cell/robot/{link}"]
        t = np.array(c["time"])
        assert t[0] == pytest.approx(0.0) and t[-1] == pytest.approx(ex.duration, abs=1e-6)
        assert np.all(np.diff(t) > 0.0) and len(t) == pytest.approx(ex.duration * RATE_HZ, rel=0.05)
    # the poses are the arm's at those instants: link_6 and the eye-in-hand camera where the executed q puts them
    X = arm.model.fk_frames(ex.q[-1], ("link_6", "camera_optical"))
    np.testing.assert_allclose(
        cols["/cell/robot/link_6"]["Transform3D:translation"][-1][0], X["link_6"][:3, 3], atol=1e-6
    )
    eye = cols["/cell/cameras/eye_in_hand"]
    assert len(eye["time"]) == len(cols["/cell/robot/link_6"]["time"])
    np.testing.assert_allclose(eye["Transform3D:translation"][-1][0], X["camera_optical"][:3, 3], atol=1e-6)
    # the TCP now and the executed tool path agree with the station's record (frame R)
    p_R = transform_points(invert(fence1_run.detection.scenario.X_WR), ex.tcp_W)
    np.testing.assert_allclose(cols["/cell/tcp/now"]["Points3D:positions"][-1][0], p_R[-1], atol=2e-3)
    (path,) = cols["/cell/tcp/path"]["LineStrips3D:strips"]
    assert len(path[0]) == len(p_R)


def test_arc_on_intervals_one_strip_per_weld(
    recorded: tuple[Path, dict[str, Any]], fence1_run: pipeline.WeldRun
) -> None:
    _, cols = recorded
    plan, ex = fence1_run.plan, fence1_run.execution
    assert plan is not None
    welds = [s for s in plan.segments if s.arc_on]
    (strips,) = cols["/cell/tcp/arc_on"]["LineStrips3D:strips"]
    assert len(strips) == len(welds) > 0  # one strip per weld the arm made (fence1: 12)
    arc = np.array(cols["/plots/arc"]["Scalars:scalars"]).ravel()
    assert set(arc) == {0.0, 1.0}
    assert ex is not None and arc.mean() == pytest.approx(plan.arc_time / ex.duration, abs=0.02)  # even in time
    texts = [x for row in cols["/log"]["TextLog:text"] for x in row]
    for kind in ("arc_on", "arc_off"):  # every switch named by its seam, in welding order
        seams = [x.split()[1] for x in texts if x.startswith(kind)]
        assert seams == [s.seam_id for s in welds]


def test_a_preview_records_the_plan_on_the_same_timeline(fence1_run: pipeline.WeldRun, tmp_path: Path) -> None:
    """Without an execution (``cell preview``) the motion is the plan's: the move home, then the program (the
    run's view as the pipeline makes it for a preview)."""
    ex, plan, pre, arm = fence1_run.execution, fence1_run.plan, fence1_run.pre_move, fence1_run.arm
    assert ex is not None and plan is not None and pre is not None and arm is not None
    view = cell_view(fence1_run.detection.scenario, arm, plan, pre)
    path = record_run(replace(fence1_run, execution=None, view=view), tmp_path / "preview.rrd")
    store = RrdReader(path).store()
    (entry,) = RrdReader(path).recordings()
    assert entry.recording_id != recording_id(fence1_run)  # a preview is another recording than the weld
    seen: dict[str, Any] = {}
    for chunk in store.stream():
        batch = chunk.to_record_batch()
        seen[chunk.entity_path] = batch
    t = seen["/cell/robot/link_6"].column("time").cast(pa.int64()).to_numpy() / 1e9
    assert t[0] == 0.0 and t[-1] == pytest.approx(pre.duration + plan.cycle_time, abs=1e-6)
    assert t[-1] == pytest.approx(ex.duration, abs=0.01)
    assert (
        len(seen["/cell/tcp/arc_on"].column("LineStrips3D:strips").to_pylist()[0])
        == len([s for s in plan.segments if s.arc_on])
        > 0
    )


def test_a_run_that_failed_early_still_records_what_it_has(fence1_run: pipeline.WeldRun, tmp_path: Path) -> None:
    """Perception lost and nothing planned: the map, the seams as the map draws them, the cell and the robot at
    its scan pose, no cloud, no motion (``--rerun`` is written whatever happens)."""
    det = replace(fence1_run.detection, scene=None)
    assert fence1_run.arm is not None
    view = cell_view(det.scenario, fence1_run.arm, None)  # as the pipeline makes it without a plan
    run = replace(fence1_run, detection=det, plan=None, execution=None, pre_move=None, view=view)
    path = record_run(run, tmp_path / "failed.rrd")
    entities = {c.entity_path: c for c in RrdReader(path).store().stream()}
    assert "/cell/cloud" not in entities and "/cell/tcp/path" not in entities and "/plots/arc" not in entities
    assert {"/cell/map/parts", "/cell/seams/found", "/cell/table", "/cell/cameras/eye_in_hand"} <= set(entities)
    base = entities["/cell/robot/link_3"]
    assert base.num_rows == 1 and base.timeline_names == ["time"]
