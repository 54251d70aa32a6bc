"""A printed calibration board in the simulated cell: a thin plate whose face carries the board's image as a texture
(the real detector then runs on rendered pixels), and the colour image's sensor model (lens blur, pixel noise)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import numpy.typing as npt
from PIL import Image
from scipy.ndimage import gaussian_filter
from scipy.spatial.transform import Rotation

from cell.geometry import FloatArray
from cell.sim.quiet import BulletClient, pybullet

Size2 = tuple[float, float]  # a width and a height, or a point in a plane [m]


def add_board(client: BulletClient, image: npt.ArrayLike, face_m: Size2, origin_m: Size2) -> int:
    """A textured plate, visual only; returns its PyBullet body id. Its frame is the board's B (the printed face in
    the plane z = 0 looking along -z, x along the image's columns, y down its rows).

    image : (h, w) uint8 grey picture of the whole printed face; face_m : its width and height [m];
    origin_m : where the image's top-left corner lies in B [m] (minus the margin around the pattern).
    """
    picture = np.asarray(image, dtype=np.uint8)
    with tempfile.TemporaryDirectory() as folder:  # PyBullet loads textures from files only
        path = Path(folder) / "board.png"
        Image.fromarray(picture).convert("RGB").save(path)
        texture = client.loadTexture(str(path))
    x0, y0 = origin_m
    x1, y1 = x0 + face_m[0], y0 + face_m[1]
    vertices = [[x0, y0, 0.0], [x1, y0, 0.0], [x1, y1, 0.0], [x0, y1, 0.0]]
    uvs = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]  # the renderer's texture rows run bottom-up
    both_sides = [0, 2, 1, 0, 3, 2, 0, 1, 2, 0, 2, 3]
    face = client.createVisualShape(
        pybullet.GEOM_MESH, vertices=vertices, indices=both_sides, uvs=uvs, normals=[[0.0, 0.0, -1.0]] * 4
    )
    body = client.createMultiBody(baseMass=0.0, baseVisualShapeIndex=face)
    client.changeVisualShape(body, -1, textureUniqueId=texture, rgbaColor=[1.0, 1.0, 1.0, 1.0])
    return int(body)


def place_body(client: BulletClient, body: int, X_W: FloatArray) -> None:
    """Put ``body`` at X_W (4, 4) in W."""
    q = Rotation.from_matrix(np.asarray(X_W)[:3, :3]).as_quat()  # scipy and PyBullet: (x, y, z, w) both
    client.resetBasePositionAndOrientation(body, [float(v) for v in X_W[:3, 3]], [float(v) for v in q])


def colour_noise(rgb: npt.ArrayLike, blur_px: float, sigma: float, rng: np.random.Generator) -> npt.NDArray[np.uint8]:
    """A rendered colour image (h, w, 3) uint8 as a camera gives it: its lens' blur (a Gaussian of ``blur_px``
    [px]) and pixel noise of ``sigma`` grey levels, rounded back to 8 bits."""
    img = np.asarray(rgb, dtype=float)
    if blur_px > 0.0:
        img = gaussian_filter(img, sigma=(blur_px, blur_px, 0.0))
    if sigma > 0.0:
        img = img + rng.normal(0.0, sigma, img.shape)
    return np.asarray(np.clip(np.rint(img), 0, 255), dtype=np.uint8)
