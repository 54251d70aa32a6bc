"""A calibration recorded as a ROS 2 bag, read into a :class:`~cell.recorded.board_capture.BoardCapture`: each
camera's colour images of the board (``sensor_msgs/Image`` ``rgb8``, ``bgr8`` or ``mono8``, with the ``CameraInfo``
beside them: pinhole and plumb_bob distortion), the depth image nearest each (``16UC1`` / ``32FC1`` in the same
namespace; optional), and the flange's pose at each image's stamp from tf (``robot_state_publisher``'s base ->
``tool0`` chain). A camera whose optical frame hangs below a moving tf edge rides on the arm (eye-in-hand), else it
is fixed. The board is not in a bag: the caller states it. Bad input is a one-line CaptureError naming the bag."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cell.recorded.bag import CAMERA_INFO, IMAGE, base_frame_of, decode, open_bag, tf_tree_of
from cell.recorded.board_capture import BoardCapture, BoardShot
from cell.recorded.ros_msgs import DEPTH_SCALE_M, camera_names, depth_of, fail, info_topic_of, stamp_ns
from cell.recorded.tf_tree import TfError, TfTree, frame_name
from cell.types import CameraIntrinsics

COLOUR = ("rgb8", "bgr8", "mono8")
FLANGE = "tool0"
Progress = Callable[[str], None]


def is_bag(path: Path) -> bool:
    """Whether ``path`` is a ROS 2 bag (a rosbag2 folder, or its .mcap / .db3 file) rather than a capture folder."""
    return path.suffix in (".mcap", ".db3") or (path.is_dir() and (path / "metadata.yaml").is_file())


def read_board_bag(
    bag: Path,
    board: Mapping[str, Any],
    cameras: Sequence[str] | None = None,
    *,
    base_frame: str | None = None,
    max_gap_s: float = 0.05,
    progress: Progress = lambda _m: None,
) -> BoardCapture:
    """The bag's board images as a capture (only ``cameras``' when given): ``board`` the board as printed
    (``calibration.board``'s keys); ``base_frame`` as :func:`cell.recorded.bag.read_bag`'s; a depth image or a
    tf sample further than ``max_gap_s`` from an image's stamp is refused (the arm may have been moving)."""
    with open_bag(bag) as reader:
        return _read(reader, bag, board, cameras, base_frame, int(max_gap_s * 1e9), progress)


def _read(
    reader: Any,
    bag: Path,
    board: Mapping[str, Any],
    wanted: Sequence[str] | None,
    base_frame: str | None,
    max_gap_ns: int,
    progress: Progress,
) -> BoardCapture:
    by_topic: dict[str, list[Any]] = {}
    for c in reader.connections:
        by_topic.setdefault(c.topic, []).append(c)
    images = {t: _messages(reader, cs, bag) for t, cs in by_topic.items() if cs[0].msgtype == IMAGE}
    colour = sorted(t for t, ms in images.items() if ms and str(ms[0][1].encoding) in COLOUR)
    depth = [t for t, ms in images.items() if ms and str(ms[0][1].encoding) in DEPTH_SCALE_M]
    if not colour:
        raise fail(bag, f"holds no colour images of the board ({', '.join(COLOUR)} {IMAGE})")
    names = camera_names(colour)
    unknown = [c for c in wanted or () if c not in names.values()]
    if unknown:
        raise fail(bag, f"no camera {', '.join(unknown)}; cameras: {', '.join(names.values())}")
    tree = tf_tree_of(reader, bag)
    base = base_frame_of(tree, base_frame, bag)
    if FLANGE not in tree.frames:
        raise fail(bag, f"its tf has no flange frame {FLANGE!r}: the arm's pose at each image is not known")
    mounts: dict[str, str] = {}
    intrinsics: dict[str, CameraIntrinsics] = {}
    shots: list[BoardShot] = []
    for topic in colour:
        name = names[topic]
        if wanted and name not in wanted:
            continue
        info_topic = info_topic_of(topic)
        if info_topic not in by_topic or by_topic[info_topic][0].msgtype != CAMERA_INFO:
            raise fail(bag, f"{topic} has no {CAMERA_INFO} beside it (expected on {info_topic})")
        info = _messages(reader, by_topic[info_topic], bag)[0][1]
        k = lens_intrinsics(info, bag, info_topic)
        first = topic.strip("/").split("/")[0]
        beside = [t for t in depth if t.strip("/").split("/")[0] == first]
        frame = frame_name(str(images[topic][0][1].header.frame_id) or str(info.header.frame_id))
        mounts[name] = _mount(tree, base, frame, images[topic][0][0])
        intrinsics[name] = k
        for stamp, msg in images[topic]:
            rgb = colour_of(msg, bag, topic)
            if rgb.shape[:2] != (k.height, k.width):
                raise fail(
                    bag, f"{topic} is {rgb.shape[1]} x {rgb.shape[0]} px, its CameraInfo says {k.width} x {k.height}"
                )
            z = _nearest_depth(images[beside[0]], stamp, max_gap_ns, bag, beside[0]) if beside else None
            shots.append(BoardShot(name, _flange(tree, base, stamp, max_gap_ns, bag, topic), rgb, _depth(z, k)))
        progress(f"{name}: {len(images[topic])} board images on {topic} ({mounts[name]})")
    return BoardCapture(dict(board), mounts, intrinsics, tuple(shots))


def _messages(reader: Any, conns: Sequence[Any], bag: Path) -> list[tuple[int, Any]]:
    """(stamp [ns], message) of every message on ``conns``, in stamp order (the record time without a header)."""
    out = []
    for conn, ts, raw in reader.messages(connections=conns):
        msg = decode(reader, raw, conn.msgtype, bag, conn.topic)
        out.append((stamp_ns(msg) or ts, msg))
    return sorted(out, key=lambda m: m[0])


def lens_intrinsics(info: Any, bag: Path, topic: str) -> CameraIntrinsics:
    """The pinhole and plumb_bob lens (k1, k2, p1, p2, k3) of a CameraInfo; another distortion model is refused."""
    K = np.asarray(info.k, dtype=float).reshape(3, 3)
    D = [float(v) for v in np.asarray(info.d, dtype=float)]
    model = str(info.distortion_model)
    if any(D) and model not in ("plumb_bob", "rational_polynomial"):
        raise fail(bag, f"{topic}: distortion model {model!r}; valid: plumb_bob (k1, k2, p1, p2, k3)")
    if len(D) > 5 and any(D[5:]):
        raise fail(bag, f"{topic}: {len(D)} distortion coefficients with k4-k6 set; valid: plumb_bob's five")
    D = (D + [0.0] * 5)[:5]
    if not (K[0, 0] > 0 and K[1, 1] > 0 and K[0, 1] == 0 and np.allclose(K[2], [0, 0, 1])):
        raise fail(bag, f"{topic}: K = {K.ravel().tolist()} is not a pinhole without skew")
    lens = (D[0], D[1], D[2], D[3], D[4])
    return CameraIntrinsics(int(info.width), int(info.height), K[0, 0], K[1, 1], K[0, 2], K[1, 2], lens)


def colour_of(msg: Any, bag: Path, topic: str) -> npt.NDArray[np.uint8]:
    """(height, width, 3) uint8 RGB of an ``rgb8`` / ``bgr8`` / ``mono8`` Image message."""
    enc, h, w, step = str(msg.encoding), int(msg.height), int(msg.width), int(msg.step)
    channels = 1 if enc == "mono8" else 3
    data = np.asarray(msg.data, dtype=np.uint8)
    if h <= 0 or w <= 0 or step < w * channels or data.size < step * h:
        raise fail(bag, f"{topic}: a {w} x {h} {enc} image needs {w * channels} bytes a row, holds step {step}")
    px = np.ascontiguousarray(data[: step * h].reshape(h, step)[:, : w * channels]).reshape(h, w, channels)
    if enc == "mono8":
        return np.repeat(px, 3, axis=2)
    return px[..., ::-1].copy() if enc == "bgr8" else px


def _nearest_depth(
    depths: list[tuple[int, Any]], stamp: int, max_gap_ns: int, bag: Path, topic: str
) -> npt.NDArray[np.float32]:
    at, msg = min(depths, key=lambda m: abs(m[0] - stamp))
    if abs(at - stamp) > max_gap_ns:
        raise fail(bag, f"{topic}: no depth image within {max_gap_ns * 1e-9:g} s of the colour image at {stamp} ns")
    return depth_of(msg, bag, topic)


def _depth(z: npt.NDArray[np.float32] | None, k: CameraIntrinsics) -> npt.NDArray[np.float32]:
    """The depth image, or all invalid (0) when the bag holds none for the camera (no depth scale is checked)."""
    if z is None:
        return np.zeros((k.height, k.width), dtype=np.float32)
    return z


def _flange(tree: TfTree, base: str, stamp: int, max_gap_ns: int, bag: Path, topic: str) -> npt.NDArray[np.float64]:
    try:
        look = tree.lookup(base, FLANGE, stamp)
    except TfError as e:
        raise fail(bag, f"{topic}: {e}") from None
    if look.max_gap_ns > max_gap_ns:
        raise fail(
            bag,
            f"{topic}: the flange's tf sample nearest the image at {stamp} ns is {look.max_gap_ns * 1e-9:.3f} s from "
            f"it; valid: within {max_gap_ns * 1e-9:g} s (the arm still at the pose)",
        )
    return np.asarray(look.X_BF, dtype=float)


def _mount(tree: TfTree, base: str, frame: str, stamp: int) -> str:
    """``eye_in_hand`` when the camera's frame hangs below a moving tf edge, else ``fixed`` (also when tf does not
    know the frame: a fixed camera's pose is what the calibration measures)."""
    if not frame or frame not in tree.frames:
        return "fixed"
    try:
        return "eye_in_hand" if tree.lookup(base, frame, stamp).moving else "fixed"
    except TfError:
        return "fixed"
