"""The simulator's camera images, drawn by PyBullet's TinyRenderer and kept by the scene and the camera that drew
them: TinyRenderer draws the same pixels from the same bodies, poses and camera, so an image asked for again in this
process is read back, not drawn (docs/bodies.md section 1). A scene whose drawing the key cannot describe (a
textured body, a mesh given by its vertices that the cell did not register) is always drawn."""

from __future__ import annotations

import hashlib
import struct
from collections import OrderedDict
from collections.abc import Mapping

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray
from cell.sim.camera import gl_projection_matrix, gl_view_matrix, linearise_depth
from cell.sim.floor import Floor
from cell.sim.quiet import BulletClient, pybullet
from cell.types import CameraIntrinsics

Image = tuple[npt.NDArray[np.uint8], FloatArray]  # colour (H, W, 3) uint8, depth (H, W) [m]

MAX_BYTES = 400 * 2**20  # the images kept per process (a 1280 x 720 pair is about 10 MB)
_MESH = pybullet.GEOM_MESH


def scene_key(
    client: BulletClient,
    drawn: Mapping[int, bytes],
    X_WC: FloatArray,
    intrinsics: CameraIntrinsics,
    near_m: float,
    far_m: float,
) -> bytes | None:
    """A digest of everything TinyRenderer's image depends on: the camera (pose, intrinsics, clip planes) and every
    body in drawing order (its visual shapes' kind, size, colour, local frame and mesh file, its base pose and joint
    positions); ``drawn`` gives, by body id, a digest of what a shape's kind and size do not say (a mesh's vertices).
    None where a body has a texture or a vertex mesh not in ``drawn``: that scene is not kept."""
    h = hashlib.sha1()
    h.update(np.ascontiguousarray(X_WC, dtype=float).tobytes())
    h.update(repr((intrinsics, float(near_m), float(far_m))).encode())
    for i in range(client.getNumBodies()):
        body = client.getBodyUniqueId(i)
        shapes = client.getVisualShapeData(body, flags=pybullet.VISUAL_SHAPE_DATA_TEXTURE_UNIQUE_IDS)
        for shape in shapes:
            if shape[8] != -1 or (shape[2] == _MESH and not shape[4] and body not in drawn):
                return None
        h.update(repr(tuple(s[1:8] for s in shapes)).encode())
        h.update(drawn.get(body, b""))
        pos, orn = client.getBasePositionAndOrientation(body)
        h.update(struct.pack("7d", *pos, *orn))
        n = client.getNumJoints(body)
        if n:
            h.update(struct.pack(f"{n}d", *(s[0] for s in client.getJointStates(body, range(n)))))
    return h.digest()


def mesh_digest(vertices: npt.ArrayLike, triangles: npt.ArrayLike) -> bytes:
    """The digest :func:`scene_key` takes for a body drawn from these vertices (k, 3) and triangles (t, 3)."""
    h = hashlib.sha1(np.ascontiguousarray(vertices, dtype=float).tobytes())
    h.update(np.ascontiguousarray(triangles, dtype=np.int64).tobytes())
    return h.digest()


class RenderCache:
    """The images last drawn, by :func:`scene_key`, least recently used dropped beyond ``max_bytes``; read-only
    copies kept, fresh copies handed out (a caller may write into its image)."""

    def __init__(self, max_bytes: int = MAX_BYTES) -> None:
        self.max_bytes = max_bytes
        self._images: OrderedDict[bytes, Image] = OrderedDict()
        self._bytes = 0
        self.hits = 0
        self.misses = 0

    def get(self, key: bytes) -> Image | None:
        """A copy of the image kept under ``key``, or None."""
        got = self._images.get(key)
        if got is None:
            self.misses += 1
            return None
        self._images.move_to_end(key)
        self.hits += 1
        return got[0].copy(), got[1].copy()

    def put(self, key: bytes, rgb: npt.NDArray[np.uint8], depth: FloatArray) -> None:
        """Keep a copy of the image drawn for ``key``."""
        if key in self._images:
            return
        kept = (rgb.copy(), depth.copy())
        for a in kept:
            a.flags.writeable = False
        self._images[key] = kept
        self._bytes += kept[0].nbytes + kept[1].nbytes
        while self._bytes > self.max_bytes and self._images:
            _, (r, d) = self._images.popitem(last=False)
            self._bytes -= r.nbytes + d.nbytes


IMAGES = RenderCache()  # this process's: the same scene drawn again by another SimCell is read back too


def draw(
    client: BulletClient,
    drawn: Mapping[int, bytes],
    X_WC: FloatArray,
    intrinsics: CameraIntrinsics,
    near_m: float,
    far_m: float,
    cache: RenderCache = IMAGES,
    floor: Floor | None = None,
) -> Image:
    """Noise-free colour (H, W, 3) uint8 and depth (H, W) [m] (0: nothing between near and far) of ``client``'s
    scene from X_WC (4, 4) in W, read back from ``cache`` when it holds this scene's image from this camera
    (:func:`scene_key`, ``drawn`` as there); ``floor`` put in where nothing else was drawn (its body's entry in
    ``drawn`` must say it)."""
    key = scene_key(client, drawn, X_WC, intrinsics, near_m, far_m)
    if key is not None and (kept := cache.get(key)) is not None:
        return kept
    _, _, rgba, buffer, _ = client.getCameraImage(
        intrinsics.width,
        intrinsics.height,
        viewMatrix=gl_view_matrix(X_WC),
        projectionMatrix=gl_projection_matrix(intrinsics, near_m, far_m),
        renderer=pybullet.ER_TINY_RENDERER,
        flags=pybullet.ER_NO_SEGMENTATION_MASK,
    )
    d = np.asarray(buffer, dtype=float).reshape(intrinsics.height, intrinsics.width)
    rgb = np.asarray(rgba, dtype=np.uint8).reshape(intrinsics.height, intrinsics.width, 4)[..., :3]
    depth = linearise_depth(d, near_m, far_m)
    if floor is not None:
        rgb, depth = floor.fill(rgb, depth, X_WC, intrinsics, near_m, far_m)
    if key is not None:
        cache.put(key, rgb, depth)
    return rgb, depth
