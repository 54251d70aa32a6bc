"""ROS 2 bags to a capture folder: depth images, their CameraInfo and their poses from tf (the only rosbags importer;
what is read and how: docs/bags.md). Bad input is a one-line :class:`~cell.errors.CaptureError` naming the bag."""

from __future__ import annotations

import sqlite3
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.recorded.ros_msgs import (
    DEPTH_SCALE_M,
    camera_names,
    depth_of,
    fail,
    info_topic_of,
    intrinsics_of,
    stamp_ns,
)
from cell.recorded.tf_tree import Lookup, TfError, TfTree, frame_name, pose_from_quaternion
from cell.types import DepthImage

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
DEFAULT_BASE = "base_link"  # the robot base's frame by ROS convention (REP 105 / URDF)

Progress = Callable[[str], None]


def _quiet(_: str) -> None:
    return None


@dataclass(frozen=True)
class BagCamera:
    """One camera read from a bag: its image (pose in the base frame), where it came from and how it was posed.

    stamp_ns : the image's ``header.stamp`` [ns] (the bag's record time when the header has none).
    tf : the chained transform base -> optical frame (its moving edges and the largest stamp gap).
    """

    image: DepthImage
    topic: str
    info_topic: str
    encoding: str
    frame_id: str
    stamp_ns: int
    tf: Lookup


@dataclass(frozen=True)
class BagCapture:
    """What :func:`read_bag` found: the cameras, by name, the base frame their poses are in, and the bag's tf."""

    bag: Path
    base_frame: str
    cameras: Mapping[str, BagCamera]
    tree: TfTree

    @property
    def images(self) -> dict[str, DepthImage]:
        return {name: cam.image for name, cam in self.cameras.items()}


def tf_tree_of(reader: Any, bag: Path) -> TfTree:
    """Every transform of the bag's TFMessage topics (``*tf_static`` topics static, the others stamped)."""
    tree = TfTree()
    conns = [c for c in reader.connections if c.msgtype == TF_MESSAGE]
    if not conns:
        return tree  # (rosbags reads every message when given no connection)
    for conn, _, raw in reader.messages(connections=conns):
        msg = decode(reader, raw, conn.msgtype, bag, conn.topic)
        for t in msg.transforms:
            tr, q = t.transform.translation, t.transform.rotation
            try:
                X = pose_from_quaternion([tr.x, tr.y, tr.z], [q.x, q.y, q.z, q.w])
                tree.add(
                    t.header.frame_id,
                    t.child_frame_id,
                    X,
                    static=conn.topic.endswith("tf_static"),
                    stamp_ns=stamp_ns(t),
                )
            except (TfError, ValueError) as e:
                raise fail(bag, f"{conn.topic}, {t.header.frame_id} -> {t.child_frame_id}: {e}") from None
    return tree


def decode(reader: Any, raw: Any, msgtype: str, bag: Path, topic: str) -> Any:
    """The message of ``raw`` bytes; a CaptureError when they do not decode as ``msgtype`` (a damaged bag)."""
    try:
        return reader.deserialize(raw, msgtype)
    except Exception as e:  # rosbags raises SerdeError, or struct/index errors on truncated data
        raise fail(bag, f"a {msgtype} message on {topic} does not decode ({type(e).__name__}: {e})") from None


def _pick(reader: Any, conns: Sequence[Any], target_ns: int | None) -> tuple[int, Any] | None:
    """(record time [ns], raw) of the first message on ``conns``, or the one recorded nearest ``target_ns``."""
    best: tuple[int, Any] | None = None
    for _, ts, raw in reader.messages(connections=conns):
        if target_ns is None:
            return ts, raw
        if best is None or abs(ts - target_ns) < abs(best[0] - target_ns):
            best = (ts, raw)
        elif ts > target_ns:
            break  # messages come in time order: the rest are further away
    return best


def base_frame_of(tree: TfTree, base_frame: str | None, bag: Path) -> str:
    """The robot base's tf frame: ``base_frame`` when named, else ``base_link``, else the tree's one root."""
    frames = tree.frames
    if not frames:
        raise fail(bag, f"holds no tf ({TF_MESSAGE} on /tf_static or /tf): the cameras' poses cannot be looked up")
    if base_frame is not None:
        if frame_name(base_frame) not in frames:
            raise fail(bag, f"base frame {base_frame!r} is not in tf; frames in tf: {', '.join(frames) or 'none'}")
        return frame_name(base_frame)
    if DEFAULT_BASE in frames:
        return DEFAULT_BASE
    if len(tree.roots) == 1:
        return tree.roots[0]
    roots = ", ".join(tree.roots) or "none: tf has a loop"
    raise fail(bag, f"no {DEFAULT_BASE!r} frame and {len(tree.roots)} tf roots ({roots}); name the base frame")


def read_bag(
    bag: Path,
    *,
    depth_topics: Sequence[str] | None = None,
    base_frame: str | None = None,
    time: float | None = None,
    max_tf_gap_s: float = 0.1,
    progress: Progress = _quiet,
) -> BagCapture:
    """One depth image per camera of a ROS 2 bag, posed in ``base_frame`` (module docstring).

    depth_topics : the Image topics to read (default: every Image topic whose encoding is a depth encoding).
    base_frame : the robot base's tf frame (default ``base_link`` when tf has it, else the root of the tf tree).
    time : pick each camera's image recorded nearest this many seconds after the bag's start (default: the first).
    max_tf_gap_s : refuse a camera whose moving tf sample nearest its stamp is further from it than this [s] (the
        arm's pose at the image would be a guess).
    """
    with open_bag(bag) as reader:
        return _read(reader, Path(bag), depth_topics, base_frame, time, max_tf_gap_s, progress)


@contextmanager
def open_bag(bag: Path) -> Iterator[Any]:
    """An open rosbags ``AnyReader`` on the ROS 2 bag at ``bag``, closed on leaving; a missing path, a ROS 1 bag and
    a bag that cannot be opened or read (its storage damaged past its index, also while reading) raise
    RecordedDataError naming it."""
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.rosbag2 import ReaderError
    from rosbags.typesys import Stores, get_typestore

    bag = Path(bag)
    if not bag.exists():
        raise fail(bag, "no such file or directory; valid: a rosbag2 folder (metadata.yaml) or its .db3/.mcap file")
    if bag.suffix == ".bag":
        raise fail(bag, "a ROS 1 bag is not read; valid: a ROS 2 bag (`rosbags-convert` turns one into the other)")
    try:
        reader = AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except (AnyReaderError, ReaderError, OSError) as e:  # rosbags says FileNotFoundError for a folder without metadata
        raise fail(bag, f"not a readable ROS bag ({' '.join(str(e).split())})") from None
    try:
        yield reader
    except (AnyReaderError, ReaderError, OSError, sqlite3.Error) as e:  # storage damaged past its index
        raise fail(bag, f"not a readable ROS bag ({' '.join(str(e).split())})") from None
    finally:
        reader.close()


def _read(
    reader: Any,
    bag: Path,
    depth_topics: Sequence[str] | None,
    base_frame: str | None,
    time: float | None,
    max_tf_gap_s: float,
    progress: Progress,
) -> BagCapture:
    by_topic: dict[str, list[Any]] = {}
    for c in reader.connections:
        by_topic.setdefault(c.topic, []).append(c)
    types = {t: cs[0].msgtype for t, cs in by_topic.items()}
    image_topics = sorted(t for t, m in types.items() if m == IMAGE)
    if depth_topics is not None:
        for t in depth_topics:
            if types.get(t) != IMAGE:
                raise fail(bag, f"{t} is not an {IMAGE} topic; image topics: {', '.join(image_topics) or 'none'}")
    asked = list(depth_topics) if depth_topics is not None else image_topics
    target_ns = None if time is None else int(reader.start_time + round(time * 1e9))
    tree = tf_tree_of(reader, bag)

    chosen: dict[str, tuple[int, Any]] = {}
    skipped: list[str] = []
    for topic in asked:
        picked = _pick(reader, by_topic[topic], target_ns)
        if picked is None:
            raise fail(bag, f"{topic} holds no message")
        msg = decode(reader, picked[1], IMAGE, bag, topic)
        if str(msg.encoding) not in DEPTH_SCALE_M:
            if depth_topics is not None:  # asked for by name: refused (depth_of says what is valid)
                depth_of(msg, bag, topic)
            skipped.append(f"{topic} ({msg.encoding})")
            continue
        chosen[topic] = (picked[0], msg)
    if not chosen:
        seen = ", ".join(skipped) or "none"
        raise fail(bag, f"no depth images (16UC1 or 32FC1 {IMAGE}); image topics: {seen}")
    if skipped:
        progress(f"not depth, left out: {', '.join(skipped)}")
    base = base_frame_of(tree, base_frame, bag)

    names = camera_names(list(chosen))
    cameras: dict[str, BagCamera] = {}
    for topic, (ts, msg) in chosen.items():
        info_topic = info_topic_of(topic)
        if types.get(info_topic) != CAMERA_INFO:
            raise fail(bag, f"{topic} has no {CAMERA_INFO} beside it (expected on {info_topic})")
        info_raw = _pick(reader, by_topic[info_topic], ts)
        if info_raw is None:
            raise fail(bag, f"{info_topic} holds no message")
        info = decode(reader, info_raw[1], CAMERA_INFO, bag, info_topic)
        k = intrinsics_of(info, bag, info_topic)
        depth = depth_of(msg, bag, topic)
        if depth.shape != (k.height, k.width):
            raise fail(
                bag, f"{topic} is {depth.shape[1]} x {depth.shape[0]} px, its CameraInfo says {k.width} x {k.height}"
            )
        frame = frame_name(str(msg.header.frame_id) or str(info.header.frame_id))
        if not frame:
            raise fail(bag, f"{topic} names no frame (header.frame_id is empty): its pose cannot be looked up")
        stamp = stamp_ns(msg) or ts
        try:
            look = tree.lookup(base, frame, stamp)
        except TfError as e:
            raise fail(bag, f"{topic}: {e}") from None
        if look.max_gap_ns > max_tf_gap_s * 1e9:
            raise fail(
                bag,
                f"{topic}: the tf sample of {', '.join(look.moving)} nearest the image is "
                f"{look.max_gap_ns * 1e-9:.3f} s from its stamp; valid: within max_tf_gap_s = {max_tf_gap_s:g} s",
            )
        mount = "eye_in_hand" if look.moving else "fixed"
        name = names[topic]
        image = DepthImage(camera=name, depth=depth, intrinsics=k, X_WC=look.X_BF, mount=mount)
        cameras[name] = BagCamera(image, topic, info_topic, str(msg.encoding), frame, stamp, look)
        gap = f", tf {look.max_gap_ns / 1e6:.1f} ms from its stamp" if look.moving else ""
        progress(f"{name}: {topic} {k.width} x {k.height} {msg.encoding} in {frame}, {mount}{gap}")
    return BagCapture(bag, base, cameras, tree)


def capture_from_bag(
    bag: Path,
    out_dir: Path,
    *,
    progress: Progress = _quiet,
    depth_topics: Sequence[str] | None = None,
    base_frame: str | None = None,
    time: float | None = None,
    max_tf_gap_s: float = 0.1,
) -> Path:
    """Read a ROS 2 bag (:func:`read_bag`) and write its cameras as a capture folder at ``out_dir``; returns it.

    The world is the robot base (X_WR identity: the bag's poses are in ``base_frame``). A ``16UC1`` image keeps
    its millimetre grid (its PNG's depth scale is 1 mm: the replay reads back the very floats); a ``32FC1`` image
    is stored at 0.1 mm (rounded by up to 0.05 mm: ``progress`` says so). An eye-in-hand camera whose tf chain
    passes through the flange frame (``tool0``) records the flange's pose at its stamp. ``depth_topics``,
    ``base_frame``, ``time`` and ``max_tf_gap_s`` are :func:`read_bag`'s. The provenance names
    the bag, the base frame and, per camera, its topic, stamp, frame and moving transforms.
    """
    from cell.provenance import provenance
    from cell.recorded.layout import DEFAULT_DEPTH_SCALE_M, FLANGE_FRAME, write_capture

    read = read_bag(
        bag, depth_topics=depth_topics, base_frame=base_frame, time=time, max_tf_gap_s=max_tf_gap_s, progress=progress
    )
    flange: dict[str, npt.NDArray[np.float64]] = {}
    for name, cam in read.cameras.items():
        if cam.image.mount == "eye_in_hand" and FLANGE_FRAME in read.tree.ancestors(cam.frame_id):
            flange[name] = read.tree.lookup(read.base_frame, FLANGE_FRAME, cam.stamp_ns).X_BF
    scales = {n: 1e-3 if c.encoding == "16UC1" else DEFAULT_DEPTH_SCALE_M for n, c in read.cameras.items()}
    prov = provenance(None, inputs={"bag": Path(bag)} if Path(bag).is_file() else None)
    prov["source"] = {
        "kind": "ros2_bag",
        "bag": str(Path(bag).resolve()),
        "base_frame": read.base_frame,
        "cameras": {
            n: {
                "topic": c.topic,
                "camera_info": c.info_topic,
                "encoding": c.encoding,
                "frame_id": c.frame_id,
                "stamp_ns": c.stamp_ns,
                "moving_transforms": list(c.tf.moving),
                "tf_gap_s": c.tf.max_gap_ns * 1e-9,
            }
            for n, c in read.cameras.items()
        },
    }
    return write_capture(
        out_dir, read.images, np.eye(4), provenance=prov, flange=flange, depth_scale_m=scales, warn=progress
    )
