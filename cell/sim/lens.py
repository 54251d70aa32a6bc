"""A simulated camera's sensor as it really is (:class:`Sensor`): its lens, its true focal length and depth scale
(``cameras.<name>.distortion`` and ``sensor_error``). PyBullet renders a pinhole image, a real camera's lens bends
it (Brown-Conrady). The pinhole image is rendered larger than the sensor (to hold what a
barrel lens brings into view) and each sensor pixel takes the rendered pixel its ray came from: the colour image
bilinearly, the depth image the nearest (a depth never blends across an edge). OpenCV through the calibration's
lens module (:mod:`cell.calibrate.lens`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from cell.calibrate.lens import resample, to_pinhole
from cell.geometry import FloatArray
from cell.scenario import CameraSpec
from cell.types import CameraIntrinsics


@dataclass(frozen=True)
class Lens:
    """render : the pinhole image to render (the sensor's intrinsics with a margin); map_x, map_y (h, w) : for each
    sensor pixel, the rendered pixel its ray came from."""

    render: CameraIntrinsics
    map_x: FloatArray
    map_y: FloatArray

    def colour(self, rgb: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint8]:
        return np.asarray(resample(rgb, self.map_x, self.map_y, nearest=False), dtype=np.uint8)

    def depth(self, depth: npt.ArrayLike) -> npt.NDArray[np.float32]:
        return np.asarray(resample(np.asarray(depth, np.float32), self.map_x, self.map_y, nearest=True))


def lens_for(sensor: CameraIntrinsics, distortion: tuple[float, float, float, float, float]) -> Lens | None:
    """The lens of a camera whose sensor has intrinsics ``sensor`` (its K; the lens it states is not read) and
    ``distortion`` (the true lens); None for a pinhole (no distortion: render the sensor's image directly)."""
    if not any(d != 0.0 for d in distortion):
        return None
    u, v = np.meshgrid(np.arange(sensor.width, dtype=float), np.arange(sensor.height, dtype=float))
    ideal = to_pinhole(np.column_stack([u.ravel(), v.ravel()]), sensor.K, distortion)
    over = max(
        0.0,
        -float(ideal[:, 0].min()),
        float(ideal[:, 0].max()) - (sensor.width - 1),
        -float(ideal[:, 1].min()),
        float(ideal[:, 1].max()) - (sensor.height - 1),
    )
    m = math.ceil(over) + 2  # the rendered image's margin on every side [px]
    render = replace(
        sensor, width=sensor.width + 2 * m, height=sensor.height + 2 * m, cx=sensor.cx + m, cy=sensor.cy + m
    )
    render = replace(render, distortion=(0.0, 0.0, 0.0, 0.0, 0.0))
    shape = (sensor.height, sensor.width)
    return Lens(render, ideal[:, 0].reshape(shape) + m, ideal[:, 1].reshape(shape) + m)


def true_intrinsics(spec: CameraSpec, stated: CameraIntrinsics) -> CameraIntrinsics:
    """The sensor's pinhole as it really is: the stated one with its focal length ``sensor_error.focal_scale``
    times (the principal point where stated)."""
    f = spec.sensor_error.focal_scale
    return stated if f == 1.0 else replace(stated, fx=stated.fx * f, fy=stated.fy * f)


@dataclass(frozen=True)
class Sensor:
    """What a camera really takes: ``render`` the pinhole image to render (the true focal length, wider when a lens
    bends it), its ``lens`` (None: a pinhole) and the factor its depth reads of the true depth."""

    render: CameraIntrinsics
    lens: Lens | None
    depth_scale: float

    def colour(self, rgb: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint8]:
        return rgb if self.lens is None else self.lens.colour(rgb)

    def depth(self, depth: npt.NDArray[np.float32]) -> npt.NDArray[np.float32]:
        z = depth if self.lens is None else self.lens.depth(depth)
        return z if self.depth_scale == 1.0 else np.asarray(z * np.float32(self.depth_scale), dtype=np.float32)


def sensor_for(spec: CameraSpec, stated: CameraIntrinsics) -> Sensor:
    """The sensor of the camera ``spec`` whose intrinsics are stated as ``stated``."""
    true = true_intrinsics(spec, stated)
    lens = lens_for(true, spec.distortion.coefficients)
    return Sensor(true if lens is None else lens.render, lens, spec.sensor_error.depth_scale)
