"""ROS 2 bags to capture folders (cell/recorded/bag.py) on tiny bags the tests write with rosbags: poses chained
through tf, encodings, the image nearest a time, the capture folder written, and every bad bag a one-line
CaptureError (exit 16) naming what was wrong."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest
import rosbag_factory as rf
from typer.testing import CliRunner

from cell.cli import app
from cell.errors import CaptureError
from cell.geometry import pose_from_xyz_rpy
from cell.recorded import read_capture
from cell.recorded.bag import capture_from_bag, read_bag
from cell.recorded.ros_msgs import camera_names
from cell.recorded.tf_tree import TfError, TfTree, pose_from_quaternion, quaternion_of
from cell.types import CameraIntrinsics

K = CameraIntrinsics(8, 6, 10.0, 11.0, 3.5, 2.5)
S = 1_000_000_000  # one second [ns]
T0 = 1_700_000_000 * S  # the recording's start (a wall-clock stamp, as a real bag has)
X_WB = pose_from_xyz_rpy([1.0, -2.0, 0.5], [0.0, 0.0, 0.7])  # world -> base_link
X_BM = pose_from_xyz_rpy([0.1, 0.2, 1.0], [0.1, -0.2, 0.3])  # base_link -> mount
X_MC = pose_from_xyz_rpy([0.3, 0.0, 0.05], [-np.pi / 2, 0.0, -np.pi / 2])  # mount -> fixed camera's optical frame
X_6T = pose_from_xyz_rpy([0.0, 0.0, 0.08], [0.0, 0.0, 0.0])  # link_6 -> tool0 (the flange)
X_TE = pose_from_xyz_rpy([0.05, 0.0, 0.1], [0.0, 0.2, 0.0])  # tool0 -> eye-in-hand optical frame


def X_B6(i: int) -> np.ndarray:
    """The arm's link_6 in base_link at its i-th tf sample (the arm moving)."""
    return pose_from_xyz_rpy([0.4 + 0.01 * i, 0.0, 0.8], [0.0, 0.05 * i, 0.1 * i])


def depth(value_m: float) -> np.ndarray:
    d = np.full((K.height, K.width), value_m)
    d[0, 0] = 0.0  # an invalid pixel
    return d


def tree_msgs() -> list[rf.Message]:
    """world -> base_link -> mount -> fixed_optical (static, a chain of two below the base) and base_link ->
    link_6 (moving, sampled every 0.1 s) -> tool0 -> eih_optical (static)."""
    static = [
        ("world", "base_link", X_WB, 0),
        ("base_link", "mount", X_BM, 0),
        ("mount", "fixed_optical", X_MC, 0),
        ("link_6", "tool0", X_6T, 0),
        ("tool0", "eih_optical", X_TE, 0),
    ]
    out = [rf.tf(static, static=True, t_ns=T0)]
    for i in range(11):
        t = T0 + i * S // 10
        out.append(rf.tf([("base_link", "link_6", X_B6(i), t)], static=False, t_ns=t))
    return out


def camera(name: str, frame: str, t_ns: int, value_m: float, encoding: str = "16UC1") -> list[rf.Message]:
    return [
        rf.image(f"/{name}/depth/image_rect_raw", frame, depth(value_m), t_ns, encoding),
        rf.camera_info(f"/{name}/depth/camera_info", frame, K, t_ns),
    ]


def bag(tmp_path: Path, messages: Sequence[rf.Message], name: str = "bag") -> Path:
    return rf.write_bag(tmp_path / name, messages)


@pytest.fixture
def two_cameras(tmp_path: Path) -> Path:
    """A fixed camera (16UC1) and an eye-in-hand camera (32FC1) with images at 0.31 s and 0.72 s, and an rgb8
    image topic that is not depth."""
    msgs = tree_msgs()
    for t, z in ((T0 + 310 * S // 1000, 1.2346), (T0 + 720 * S // 1000, 1.5)):
        msgs += camera("fixed_cam", "fixed_optical", t, z)
        msgs += camera("arm_cam", "eih_optical", t, z + 0.25, "32FC1")
    msgs.append(rf.image("/color/image_raw", "fixed_optical", depth(1.0), T0, "rgb8"))
    return bag(tmp_path, msgs)


def test_poses_chained_through_static_and_moving_tf(two_cameras: Path) -> None:
    read = read_bag(two_cameras)
    assert read.base_frame == "base_link"  # the robot base by convention, not the tree's root (world)
    fixed, eih = read.cameras["fixed_cam"].image, read.cameras["arm_cam"].image
    np.testing.assert_allclose(fixed.X_WC, X_BM @ X_MC, atol=1e-12)
    assert fixed.mount == "fixed" and eih.mount == "eye_in_hand"
    # The image at 0.31 s takes the arm's sample at 0.3 s (the nearest): the camera is posed where the arm was.
    np.testing.assert_allclose(eih.X_WC, X_B6(3) @ X_6T @ X_TE, atol=1e-12)
    assert read.cameras["arm_cam"].tf.moving == ("base_link->link_6",)
    assert read.cameras["arm_cam"].tf.max_gap_ns == 10_000_000
    assert fixed.intrinsics == K and eih.intrinsics == K


def test_encodings_and_the_image_nearest_a_time(two_cameras: Path) -> None:
    first = read_bag(two_cameras).images
    assert first["fixed_cam"].depth[1, 1] == np.float32(1.235)  # 16UC1: whole millimetres
    assert first["arm_cam"].depth[1, 1] == np.float32(1.4846)  # 32FC1: metres as recorded
    assert first["fixed_cam"].depth[0, 0] == 0.0 and first["arm_cam"].depth[0, 0] == 0.0
    later = read_bag(two_cameras, time=0.7)
    assert later.images["fixed_cam"].depth[1, 1] == np.float32(1.5)
    np.testing.assert_allclose(later.images["arm_cam"].X_WC, X_B6(7) @ X_6T @ X_TE, atol=1e-12)
    world = read_bag(two_cameras, base_frame="world", depth_topics=["/fixed_cam/depth/image_rect_raw"])
    assert list(world.cameras) == ["fixed_cam"]
    np.testing.assert_allclose(world.images["fixed_cam"].X_WC, X_WB @ X_BM @ X_MC, atol=1e-12)


def test_capture_folder_written_from_a_bag(two_cameras: Path, tmp_path: Path) -> None:
    folder = capture_from_bag(two_cameras, tmp_path / "capture")
    rec = read_capture(folder)
    read = read_bag(two_cameras)
    np.testing.assert_array_equal(rec.X_WR, np.eye(4))
    for name, image in read.images.items():
        np.testing.assert_allclose(rec.X_RC(name), image.X_WC, atol=1e-12)
        assert rec.images[name].mount == image.mount
    # 16UC1 keeps its millimetre grid: the folder gives back the very floats; 32FC1 is stored at 0.1 mm.
    np.testing.assert_array_equal(rec.images["fixed_cam"].depth, read.images["fixed_cam"].depth)
    assert rec.depth_scale_m == {"fixed_cam": 1e-3, "arm_cam": 1e-4}
    assert np.abs(rec.images["arm_cam"].depth - read.images["arm_cam"].depth).max() <= 0.5e-4 + 1e-7
    np.testing.assert_allclose(rec.X_RF["arm_cam"], X_B6(3) @ X_6T, atol=1e-12)  # tool0 at the image's stamp
    assert "fixed_cam" not in rec.X_RF
    assert rec.provenance is not None and rec.provenance["source"]["base_frame"] == "base_link"


def test_tf_tree_refuses_two_parents_and_round_trips_quaternions() -> None:
    tree = TfTree()
    tree.add("a", "b", np.eye(4), static=True)
    with pytest.raises(TfError, match="two parents"):
        tree.add("c", "b", np.eye(4), static=True)
    rng = np.random.default_rng(3)
    for _ in range(20):
        X = pose_from_xyz_rpy(rng.normal(size=3), rng.uniform(-3, 3, size=3))
        np.testing.assert_allclose(pose_from_quaternion(X[:3, 3], quaternion_of(X[:3, :3])), X, atol=1e-12)


def _refused(path: Path, match: str, **kwargs: object) -> CaptureError:
    with pytest.raises(CaptureError, match=match) as info:
        read_bag(path, **kwargs)  # type: ignore[arg-type]
    assert "\n" not in info.value.message and info.value.exit_code == 16
    return info.value


def test_bad_bags_are_one_line_capture_errors(tmp_path: Path) -> None:
    text = tmp_path / "notes.txt"
    text.write_text("not a bag")
    _refused(text, "not a readable ROS bag")
    (tmp_path / "empty").mkdir()
    _refused(tmp_path / "empty", "not a readable ROS bag")
    _refused(tmp_path / "missing", "no such file")
    t = T0 + S // 10
    good = camera("cam", "fixed_optical", t, 1.0)
    cases: dict[str, tuple[list[rf.Message], str]] = {
        "no_depth": (
            [*tree_msgs(), rf.image("/color/image_raw", "fixed_optical", depth(1.0), t, "rgb8")],
            r"no depth images .*/color/image_raw \(rgb8\)",
        ),
        "no_info": ([*tree_msgs(), good[0]], r"no sensor_msgs/msg/CameraInfo beside it .*/cam/depth/camera_info"),
        "no_path": (
            [
                *tree_msgs(),
                *camera("cam", "lost_optical", t, 1.0),
                rf.tf([("elsewhere", "lost_optical", np.eye(4), 0)], static=True, t_ns=T0),
            ],
            r"no tf path from 'base_link' to 'lost_optical'",
        ),
        "no_tf": (good, r"holds no tf \(tf2_msgs/msg/TFMessage on /tf_static or /tf\)"),
        "no_frame": ([*tree_msgs(), *camera("cam", "unknown_optical", t, 1.0)], r"'unknown_optical' is not in tf"),
        "size": (
            [*tree_msgs(), rf.image("/cam/depth/image_rect_raw", "fixed_optical", np.ones((4, 8)), t), good[1]],
            r"is 8 x 4 px, its CameraInfo says 8 x 6",
        ),
        "distorted": (
            [
                *tree_msgs(),
                good[0],
                rf.camera_info("/cam/depth/camera_info", "fixed_optical", K, t, d=(0.1, 0.0, 0.0, 0.0, 0.0)),
            ],
            r"distortion plumb_bob .* is not zero",
        ),
    }
    for name, (msgs, match) in cases.items():
        _refused(bag(tmp_path, msgs, name), match)
    mono = bag(tmp_path, [*tree_msgs(), rf.image("/cam/depth/image_raw", "fixed_optical", depth(1.0), t, "mono8")])
    _refused(mono, r"encoding 'mono8'; valid depth encodings: 16UC1", depth_topics=["/cam/depth/image_raw"])
    _refused(mono, r"/nope is not an sensor_msgs/msg/Image topic", depth_topics=["/nope"])
    _refused(bag(tmp_path, [*tree_msgs(), *good], "base"), r"base frame 'robot' is not in tf", base_frame="robot")


def test_stale_tf_damaged_data_ros1_and_name_clashes(tmp_path: Path) -> None:
    late = T0 + 3 * S  # 2 s after the arm's last tf sample: its pose at the image is not known
    stale = bag(tmp_path, [*tree_msgs(), *camera("arm_cam", "eih_optical", late, 1.0)], "stale")
    _refused(stale, r"base_link->link_6 nearest the image is 2.000 s from its stamp; valid: within max_tf_gap_s")
    assert read_bag(stale, max_tf_gap_s=3.0).cameras["arm_cam"].tf.max_gap_ns == 2 * S
    damaged = rf.Message("/cam/depth/image_raw", "sensor_msgs/msg/Image", T0, None)
    with rf.Writer(tmp_path / "damaged", version=9) as writer:
        conn = writer.add_connection(damaged.topic, damaged.msgtype, typestore=rf.TYPESTORE)
        writer.write(conn, T0, b"\x00\x01\x00\x00 not cdr")
    _refused(tmp_path / "damaged", r"a sensor_msgs/msg/Image message on /cam/depth/image_raw does not decode")
    ros1 = tmp_path / "old.bag"
    ros1.write_bytes(b"#ROSBAG V2.0\n")
    _refused(ros1, "a ROS 1 bag is not read")
    assert camera_names(["/a/depth/image_raw", "/b/depth/image_raw"]) == {
        "/a/depth/image_raw": "a",
        "/b/depth/image_raw": "b",
    }
    assert camera_names(["/cam/depth/image_raw", "/cam/ir/image_raw"]) == {
        "/cam/depth/image_raw": "cam_depth",
        "/cam/ir/image_raw": "cam_ir",
    }
    assert camera_names(["/cam/depth", "/cam/depth2"]) == {"/cam/depth": "cam_depth", "/cam/depth2": "cam_depth2"}


def test_cli_converts_a_bag_and_refuses_a_bad_one(two_cameras: Path, tmp_path: Path) -> None:
    out = tmp_path / "capture"
    result = CliRunner().invoke(app, ["capture", "--from-bag", str(two_cameras), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert set(read_capture(out).images) == {"fixed_cam", "arm_cam"}
    one = tmp_path / "one"  # the bag's options reach the reader: one topic, a named base frame
    argv = [
        "capture",
        "--from-bag",
        str(two_cameras),
        "--out",
        str(one),
        "--depth-topic",
        "/arm_cam/depth/image_rect_raw",
    ]
    result = CliRunner().invoke(app, [*argv, "--base-frame", "base_link", "--max-tf-gap", "0.05"])
    assert result.exit_code == 0, result.output
    assert set(read_capture(one).images) == {"arm_cam"}
    result = CliRunner().invoke(app, ["capture", "fence1", "--out", str(tmp_path / "c3"), "--time", "1.0"])
    assert result.exit_code == 2 and "--time only apply to --from-bag" in result.output
    notes = tmp_path / "notes.txt"
    notes.write_text("not a bag")
    result = CliRunner().invoke(app, ["capture", "--from-bag", str(notes), "--out", str(tmp_path / "c2")])
    assert result.exit_code == 16
    assert "Traceback" not in result.output and "not a readable ROS bag" in result.output
