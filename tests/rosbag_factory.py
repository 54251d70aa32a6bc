"""Small ROS 2 bags written by the tests with rosbags (no ROS install): depth images, CameraInfo and tf.

Messages are built from the ROS 2 Humble typestore and written CDR-serialised into a rosbag2 folder (MCAP or
sqlite3 storage), the layout ``ros2 bag record`` makes. Poses are (4, 4) [m], depths float [m], stamps integer
nanoseconds.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from cell.recorded.tf_tree import quaternion_of
from cell.types import CameraIntrinsics

TYPESTORE = get_typestore(Stores.ROS2_HUMBLE)
T = TYPESTORE.types
# The ROS optical frame in its camera link (REP 103): z forward, x right, y down in a link x forward, z up.
X_LINK_OPTICAL = np.array([[0.0, 0.0, 1.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class Message:
    """One message to write: topic, type name, record time [ns] and the message object."""

    topic: str
    msgtype: str
    t_ns: int
    msg: Any


def _header(frame: str, stamp_ns: int) -> Any:
    stamp = T["builtin_interfaces/msg/Time"](sec=stamp_ns // 1_000_000_000, nanosec=stamp_ns % 1_000_000_000)
    return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


def image(topic: str, frame: str, depth_m: npt.ArrayLike, stamp_ns: int, encoding: str = "16UC1") -> Message:
    """A depth Image: ``16UC1`` rounds to whole millimetres, ``32FC1`` keeps float32 metres; any other encoding
    stores the raw bytes of ``depth_m`` as uint8 (for refusal tests)."""
    z = np.asarray(depth_m, dtype=np.float64)
    h, w = z.shape
    if encoding == "16UC1":
        data = np.round(np.nan_to_num(z) * 1000.0).astype("<u2").view(np.uint8).ravel()
    elif encoding == "32FC1":
        data = z.astype("<f4").view(np.uint8).ravel()
    else:
        data = z.astype(np.uint8).ravel()
    step = data.size // h
    msg = T["sensor_msgs/msg/Image"](
        header=_header(frame, stamp_ns), height=h, width=w, encoding=encoding, is_bigendian=0, step=step, data=data
    )
    return Message(topic, "sensor_msgs/msg/Image", stamp_ns, msg)


def colour_image(topic: str, frame: str, rgb: npt.ArrayLike, stamp_ns: int, encoding: str = "rgb8") -> Message:
    """A colour Image of (h, w, 3) uint8 RGB pixels, stored as ``rgb8`` or ``bgr8``."""
    px = np.asarray(rgb, dtype=np.uint8)
    h, w = px.shape[:2]
    data = (px[..., ::-1] if encoding == "bgr8" else px).ravel().copy()
    msg = T["sensor_msgs/msg/Image"](
        header=_header(frame, stamp_ns), height=h, width=w, encoding=encoding, is_bigendian=0, step=3 * w, data=data
    )
    return Message(topic, "sensor_msgs/msg/Image", stamp_ns, msg)


def camera_info(topic: str, frame: str, k: CameraIntrinsics, stamp_ns: int, d: Sequence[float] = (0.0,) * 5) -> Message:
    """A CameraInfo of pinhole intrinsics ``k`` (plumb_bob with coefficients ``d``)."""
    K = np.array([k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0])
    P = np.array([k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0])
    roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
    msg = T["sensor_msgs/msg/CameraInfo"](
        header=_header(frame, stamp_ns),
        height=k.height,
        width=k.width,
        distortion_model="plumb_bob",
        d=np.asarray(d, dtype=np.float64),
        k=K,
        r=np.eye(3).ravel(),
        p=P,
        binning_x=0,
        binning_y=0,
        roi=roi,
    )
    return Message(topic, "sensor_msgs/msg/CameraInfo", stamp_ns, msg)


def tf(transforms: Sequence[tuple[str, str, npt.ArrayLike, int]], *, static: bool, t_ns: int = 0) -> Message:
    """A TFMessage of (parent, child, X_PC, stamp [ns]) on ``/tf_static`` or ``/tf``."""
    out = []
    for parent, child, X, stamp in transforms:
        X = np.asarray(X, dtype=float)
        qx, qy, qz, qw = quaternion_of(X[:3, :3])
        tr = T["geometry_msgs/msg/Transform"](
            translation=T["geometry_msgs/msg/Vector3"](x=X[0, 3], y=X[1, 3], z=X[2, 3]),
            rotation=T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
        )
        out.append(
            T["geometry_msgs/msg/TransformStamped"](header=_header(parent, stamp), child_frame_id=child, transform=tr)
        )
    topic = "/tf_static" if static else "/tf"
    return Message(topic, "tf2_msgs/msg/TFMessage", t_ns, T["tf2_msgs/msg/TFMessage"](transforms=out))


def write_bag(path: Path, messages: Sequence[Message], *, storage: str = "mcap") -> Path:
    """A rosbag2 folder at ``path`` (which must not exist) holding ``messages`` in record-time order; ``storage``
    ``mcap`` (the default of ROS 2 since Iron; fast to write) or ``sqlite3`` (Humble's default)."""
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        conns: dict[str, Any] = {}
        for m in sorted(messages, key=lambda m: m.t_ns):
            if m.topic not in conns:
                conns[m.topic] = writer.add_connection(m.topic, m.msgtype, typestore=TYPESTORE)
            writer.write(conns[m.topic], m.t_ns, TYPESTORE.serialize_cdr(m.msg, m.msgtype))
    return path
