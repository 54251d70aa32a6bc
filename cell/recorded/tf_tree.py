"""A tf tree as a recording holds it: static and timed transforms between named frames, chained on demand, each
moving edge taken at its sample nearest the asked stamp (docs/bags.md, "Poses from tf"). Numpy only; frames are
names without a leading ``/``, poses ``X_PC`` (4, 4) [m], stamps integer nanoseconds."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, invert


class TfError(ValueError):
    """The tree cannot answer: a frame with two parents, a frame nobody published, no path between two frames.
    The bag reader turns it into the project's error (one line, what is valid)."""


def frame_name(name: str) -> str:
    """tf2's form of a frame name: no leading slash."""
    return name.lstrip("/")


def pose_from_quaternion(t: npt.ArrayLike, q_xyzw: npt.ArrayLike) -> FloatArray:
    """(4, 4) pose from a translation (3,) [m] and a quaternion in ROS order (x, y, z, w), normalised here.

    ValueError when the quaternion is (nearly) zero or not finite.
    """
    x, y, z, w = (float(v) for v in np.asarray(q_xyzw, dtype=float).reshape(4))
    n = np.sqrt(x * x + y * y + z * z + w * w)
    if not np.isfinite(n) or n < 1e-6:
        raise ValueError(f"quaternion (x, y, z, w) = {(x, y, z, w)} has no rotation")
    x, y, z, w = x / n, y / n, z / n, w / n
    X = np.eye(4)
    X[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    X[:3, 3] = np.asarray(t, dtype=float).reshape(3)
    if not np.all(np.isfinite(X)):
        raise ValueError(f"translation {np.asarray(t).tolist()} is not finite")
    return X


def quaternion_of(R: FloatArray) -> FloatArray:
    """(4,) unit quaternion (x, y, z, w) of a rotation matrix (3, 3): the inverse of :func:`pose_from_quaternion`."""
    m = np.asarray(R, dtype=float)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0.0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax([m[0, 0], m[1, 1], m[2, 2]]))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i] = 0.25 * s
        q[j] = (m[j, i] + m[i, j]) / s
        q[k] = (m[k, i] + m[i, k]) / s
    out = np.asarray(q, dtype=float)
    return out / np.linalg.norm(out)


@dataclass
class _Edge:
    parent: str
    static: FloatArray | None = None  # X_PC of a static edge
    stamps_ns: list[int] = field(default_factory=list)  # a dynamic edge's samples, in arrival order
    poses: list[FloatArray] = field(default_factory=list)


@dataclass(frozen=True)
class Lookup:
    """A chained transform: ``X_BF`` (4, 4) pose of the target frame F in the base B.

    moving : the dynamic edges on the way (``"parent->child"``), from B to F; empty for a fixed chain.
    moving_frame : the child frame of the dynamic edge nearest F (the moving link F hangs below), or ``""``.
    max_gap_ns : the largest time between the asked stamp and a dynamic sample used (0 for a fixed chain).
    """

    X_BF: FloatArray
    moving: tuple[str, ...]
    moving_frame: str
    max_gap_ns: int


class TfTree:
    """Frames and the transforms between them (module docstring). Fill with :meth:`add`, ask with :meth:`lookup`."""

    def __init__(self) -> None:
        self._edges: dict[str, _Edge] = {}

    def add(self, parent: str, child: str, X_PC: FloatArray, *, static: bool, stamp_ns: int = 0) -> None:
        """One transform: child in parent (4, 4) [m]; a dynamic one stamped [ns]. TfError when ``child`` already
        has another parent, or is both static and dynamic."""
        parent, child = frame_name(parent), frame_name(child)
        if not parent or not child or parent == child:
            raise TfError(f"a transform from {parent!r} to {child!r}: both frames must be named and differ")
        edge = self._edges.setdefault(child, _Edge(parent))
        if edge.parent != parent:
            raise TfError(f"frame {child!r} has two parents in tf, {edge.parent!r} and {parent!r}; tf allows one")
        if static:
            if edge.stamps_ns:
                raise TfError(f"frame {child!r} is published both on tf_static and on tf; valid: one of them")
            edge.static = np.asarray(X_PC, dtype=float)  # a later static transform replaces the earlier (tf2 does)
        else:
            if edge.static is not None:
                raise TfError(f"frame {child!r} is published both on tf_static and on tf; valid: one of them")
            edge.stamps_ns.append(int(stamp_ns))
            edge.poses.append(np.asarray(X_PC, dtype=float))

    @property
    def frames(self) -> tuple[str, ...]:
        """Every frame named by a transform, sorted."""
        return tuple(sorted(set(self._edges) | {e.parent for e in self._edges.values()}))

    @property
    def roots(self) -> tuple[str, ...]:
        """The frames without a parent, sorted (one per connected tree)."""
        return tuple(f for f in self.frames if f not in self._edges)

    def ancestors(self, frame: str) -> list[str]:
        """``frame``, its parent, ... up to its root."""
        out = [frame_name(frame)]
        while out[-1] in self._edges:
            out.append(self._edges[out[-1]].parent)
            if len(out) > len(self._edges) + 1:
                raise TfError(f"tf has a loop through frame {frame!r}")
        return out

    def _up(self, path: list[str], stamp_ns: int) -> tuple[FloatArray, list[str], int]:
        """X_AF of the first frame F of ``path`` in its last A, the dynamic edges used (child first) and the
        largest stamp gap [ns]."""
        X = np.eye(4)
        moving: list[str] = []
        gap = 0
        for child in path[:-1]:
            edge = self._edges[child]
            if edge.static is not None:
                X_PC = edge.static
            else:
                stamps = np.asarray(edge.stamps_ns, dtype=np.int64)
                i = int(np.argmin(np.abs(stamps - stamp_ns)))
                X_PC = edge.poses[i]
                gap = max(gap, abs(int(stamps[i]) - stamp_ns))
                moving.append(child)
            X = X_PC @ X
        return X, moving, gap

    def lookup(self, base: str, frame: str, stamp_ns: int) -> Lookup:
        """Pose of ``frame`` in ``base`` at ``stamp_ns`` (module docstring); TfError when either frame is unknown
        or no chain of transforms joins them."""
        base, frame = frame_name(base), frame_name(frame)
        known = self.frames
        for f in (base, frame):
            if f not in known:
                raise TfError(f"frame {f!r} is not in tf; frames in tf: {', '.join(known) or 'none'}")
        up_f, up_b = self.ancestors(frame), self.ancestors(base)
        common = next((a for a in up_f if a in up_b), None)
        if common is None:
            raise TfError(
                f"no tf path from {base!r} to {frame!r}: they hang below different roots "
                f"({up_b[-1]!r} and {up_f[-1]!r}); a transform joining the two trees is missing"
            )
        X_AF, moving_f, gap_f = self._up(up_f[: up_f.index(common) + 1], stamp_ns)
        X_AB, moving_b, gap_b = self._up(up_b[: up_b.index(common) + 1], stamp_ns)
        names = [f"{self._edges[c].parent}->{c}" for c in (*reversed(moving_b), *moving_f)]
        return Lookup(
            X_BF=invert(X_AB) @ X_AF,
            moving=tuple(names),
            moving_frame=moving_f[0] if moving_f else "",
            max_gap_ns=max(gap_f, gap_b),
        )
