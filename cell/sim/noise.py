"""A depth-sensor error model, numpy only (docs/reference.md section 2): active stereo (D4xx) or structured light
(Kinect v1) noise, quantisation, grazing dropout and invalid or flying pixels at depth edges, driven by a
:class:`~cell.scenario.NoiseSpec` and a generator (never a global RNG); specular dropout on request.
Depth images are (H, W) [m] along the optical axis, 0 = invalid."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cell.geometry import FloatArray, axis_angle_to_matrix, make_pose
from cell.scenario import CameraSpec, ExtrinsicErrorSpec, NoiseSpec, SpecularDropoutSpec
from cell.types import CameraIntrinsics

# Kinect v1 axial noise (Nguyen, Izadi, Lovell, "Modeling Kinect sensor noise for improved 3D reconstruction
# and tracking", 3DIMPVT 2012), fitted for 10-60 deg incidence:
# sigma_z = A + B (z - Z0)^2 + C / sqrt(z) * theta^2 / (pi/2 - theta)^2.
_KINECT_A = 0.0012  # [m]
_KINECT_B = 0.0019  # [1/m]
_KINECT_Z0 = 0.4  # [m]
_KINECT_C = 0.0001  # [m^1.5]
_MAX_INCIDENCE = np.radians(89.0)  # keeps the incidence term finite [rad]


def sigma_z(z_m: npt.ArrayLike, spec: NoiseSpec, fx_px: float, incidence_rad: npt.ArrayLike = 0.0) -> FloatArray:
    """Axial (depth) noise standard deviation [m] of the model at depths ``z_m`` [m] (any shape).

    fx_px : focal length [px]; used by ``active_stereo``.
    incidence_rad : angle between the viewing ray and the surface normal [rad]; used by ``structured_light``.
    Returns an array of ``z_m``'s shape (zeros for model ``none``).
    """
    z = np.asarray(z_m, dtype=float)
    if spec.model == "active_stereo":
        return np.asarray(z**2 * spec.subpixel_px / (fx_px * spec.baseline_m))
    if spec.model == "structured_light":
        theta = np.clip(np.asarray(incidence_rad, dtype=float), 0.0, _MAX_INCIDENCE)
        incidence_term = _KINECT_C / np.sqrt(np.maximum(z, 1e-6)) * theta**2 / (np.pi / 2 - theta) ** 2
        return np.asarray(_KINECT_A + _KINECT_B * (z - _KINECT_Z0) ** 2 + incidence_term)
    return np.zeros_like(z)


def _one_sided_step(z: FloatArray, valid: npt.NDArray[np.bool_], axis: int) -> tuple[FloatArray, FloatArray]:
    """Depth step to a 4-neighbour along image ``axis`` and that neighbour's depth, each (H, W) [m].

    The step is taken on the side with the smaller depth change, so that a pixel next to a discontinuity gets
    the slope of its own surface; NaN where neither side is valid.
    """
    head = (slice(None),) * axis + (slice(None, -1),)  # every index but the last along ``axis`` (views, no copies)
    tail = (slice(None),) * axis + (slice(1, None),)  # every index but the first
    diff = np.where(valid[head] & valid[tail], z[tail] - z[head], np.nan)
    fwd = np.full(z.shape, np.nan)  # z[i+1] - z[i]
    fwd[head] = diff
    bwd = np.full(z.shape, np.nan)  # z[i] - z[i-1]
    bwd[tail] = diff
    use_bwd = np.isnan(fwd) | (np.abs(bwd) < np.abs(fwd))
    step = np.where(use_bwd, bwd, fwd)
    neighbour = np.where(use_bwd, z - bwd, z + fwd)
    return step, neighbour


def incidence_angles(depth_m: npt.ArrayLike, intrinsics: CameraIntrinsics) -> FloatArray:
    """(H, W) angle [rad] between each pixel's viewing ray and the local surface normal, from the depth image.

    The normal is the cross product of the back-projected one-sided differences to a horizontal and a vertical
    neighbour (exact on planes). With ray r = ((u - cx)/fx, (v - cy)/fy, 1) and neighbour depths z_u, z_v,
    those differences are dz_u r + a e_x and dz_v r + b e_y (a = z_u / fx, b = z_v / fy), so
    n = (-b dz_u, -a dz_v, b dz_u r_x + a dz_v r_y + a b) and n . r = a b.
    NaN where the normal cannot be estimated (invalid pixel, or no valid neighbour along a direction).
    """
    z = np.asarray(depth_m, dtype=float)
    valid = z > 0
    dz_u, z_u = _one_sided_step(z, valid, 1)
    dz_v, z_v = _one_sided_step(z, valid, 0)
    rx = ((np.arange(intrinsics.width) - intrinsics.cx) / intrinsics.fx)[None, :]
    ry = ((np.arange(intrinsics.height) - intrinsics.cy) / intrinsics.fy)[:, None]
    a = z_u / intrinsics.fx
    b = z_v / intrinsics.fy
    nx = -b * dz_u
    ny = -a * dz_v
    nz = -nx * rx - ny * ry + a * b
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.abs(a * b) / (np.sqrt(nx**2 + ny**2 + nz**2) * np.sqrt(rx**2 + ry**2 + 1.0))
        theta = np.arccos(np.clip(cos, 0.0, 1.0))
    theta[~valid] = np.nan
    return np.asarray(theta)


def depth_edges(depth_m: npt.ArrayLike, jump_m: float) -> tuple[npt.NDArray[np.bool_], FloatArray]:
    """Pixels at depth discontinuities.

    Returns ``edge`` (H, W) bool: valid pixels with a valid 4-neighbour whose depth differs by more than
    ``jump_m``; and ``other`` (H, W) [m]: the depth of the neighbour with the largest such jump (NaN where not
    an edge).
    """
    z = np.asarray(depth_m, dtype=float)
    valid = z > 0
    # Each pair of 4-neighbours' jump once (0 unless both valid), read from either side: |a - b| is |b - a|.
    down = np.where(valid[1:] & valid[:-1], np.abs(z[1:] - z[:-1]), 0.0)  # (H - 1, W): row i+1 against row i
    right = np.where(valid[:, 1:] & valid[:, :-1], np.abs(z[:, 1:] - z[:, :-1]), 0.0)  # (H, W - 1)
    best_jump = np.zeros(z.shape)
    other = np.full(z.shape, np.nan)
    jump = np.empty(z.shape)
    nb = np.empty(z.shape)
    for axis, back in ((0, True), (0, False), (1, True), (1, False)):  # up, down, left, right: ties to the first
        pair = down if axis == 0 else right
        lead: tuple[slice, ...] = (slice(None),) * axis
        own = (*lead, slice(1, None) if back else slice(None, -1))  # the pixels that have this neighbour
        far = (*lead, slice(None, -1) if back else slice(1, None))  # and the neighbour's pixels
        jump.fill(0.0)
        jump[own] = pair
        nb.fill(0.0)
        nb[own] = z[far]
        better = (jump > jump_m) & (jump > best_jump)
        np.copyto(best_jump, jump, where=better)
        np.copyto(other, nb, where=better)
    return best_jump > jump_m, other


def _quantise(x: FloatArray, step: float) -> FloatArray:
    return np.round(x / step) * step if step > 0 else x


def apply_noise(
    depth_m: npt.ArrayLike, intrinsics: CameraIntrinsics, spec: NoiseSpec, rng: np.random.Generator
) -> npt.NDArray[np.float32]:
    """A noisy copy (H, W) float32 [m] of the true depth image ``depth_m`` (H, W) [m] (0 = invalid, stays 0).

    Deterministic: the same image and the same ``rng`` state give the same result.
    """
    z = np.asarray(depth_m, dtype=float)
    if z.shape != (intrinsics.height, intrinsics.width):
        raise ValueError(f"depth image is {z.shape}, intrinsics say {(intrinsics.height, intrinsics.width)}")
    if spec.model == "none":
        return z.astype(np.float32)
    valid = z > 0
    theta = incidence_angles(z, intrinsics)
    standard_normal = rng.standard_normal(z.shape)
    if spec.model == "active_stereo":
        fB = intrinsics.fx * spec.baseline_m  # [px m]
        with np.errstate(divide="ignore"):
            disparity = np.where(valid, fB / np.where(valid, z, 1.0), 0.0)
        disparity = _quantise(disparity + spec.subpixel_px * standard_normal, spec.disparity_step_px)
        ok = valid & (disparity > 0)
        noisy = np.where(ok, fB / np.where(ok, disparity, 1.0), 0.0)
    else:  # structured_light
        sigma = sigma_z(z, spec, intrinsics.fx, np.nan_to_num(theta, nan=0.0))
        noisy = np.where(valid, np.maximum(z + sigma * standard_normal, 0.0), 0.0)
    noisy = _quantise(noisy, spec.depth_unit_m)

    # Grazing incidence: the projector pattern / texture is not seen, the pixel drops out.
    noisy[np.nan_to_num(theta, nan=0.0) > np.radians(spec.grazing_dropout_deg)] = 0.0

    # Depth discontinuities: a fraction of the edge pixels are invalid, some of those come back "flying".
    edge, other = depth_edges(z, spec.edge_jump_m)
    edge_idx = np.flatnonzero(edge)
    n_bad = round(spec.edge_invalid_fraction * edge_idx.size)
    bad = rng.permutation(edge_idx)[:n_bad]
    n_flying = round(spec.edge_flying_fraction * n_bad)
    flying, dropped = bad[:n_flying], bad[n_flying:]
    flat = noisy.reshape(-1)
    flat[dropped] = 0.0
    t = rng.uniform(0.0, 1.0, size=n_flying)
    z_own, z_other = z.reshape(-1)[flying], other.reshape(-1)[flying]
    flat[flying] = _quantise(z_own + t * (z_other - z_own), spec.depth_unit_m)
    noisy[~valid] = 0.0
    return noisy.astype(np.float32)


def specular_dropout(
    noisy_m: npt.ArrayLike,
    true_depth_m: npt.ArrayLike,
    intrinsics: CameraIntrinsics,
    spec: SpecularDropoutSpec,
    rng: np.random.Generator,
) -> npt.NDArray[np.float32]:
    """Shiny steel seen by an active-stereo camera: a copy (H, W) float32 [m] of ``noisy_m`` where each pixel whose
    true surface (``true_depth_m``, its normal from :func:`incidence_angles`) faces the camera within
    ``spec.within_deg`` is 0 with probability ``spec.fraction``.

    The projector sits beside the camera (the stereo baseline, 55 mm at 1 m and more is under 3 degrees), so its
    mirror direction on a surface is the viewing ray itself within that: a surface facing the camera reflects the
    pattern straight back (saturated) or, polished, away from the other imager; either way the matcher has no
    texture. One uniform draw per pixel from ``rng`` (the camera's ``/specular`` stream), invalid pixels stay 0.
    """
    out = np.array(noisy_m, dtype=np.float32)
    theta = incidence_angles(true_depth_m, intrinsics)
    facing = np.nan_to_num(theta, nan=np.pi) <= np.radians(spec.within_deg)
    draw = rng.uniform(0.0, 1.0, size=out.shape)
    out[facing & (draw < spec.fraction)] = 0.0
    return out


def perturb_pose(X_WC: FloatArray, spec: ExtrinsicErrorSpec, rng: np.random.Generator) -> FloatArray:
    """The pose a calibration believes: X_WC (4, 4) moved by exactly ``translation_mm`` in a random direction
    and rotated by exactly ``rotation_deg`` about a random axis through the camera centre.

    The error is applied in the camera frame (``X_WC @ X_CC'``), so a fixed error stays attached to the
    camera: the same ``rng`` state gives the same calibration error for a fixed camera and for an eye-in-hand
    camera in any pose.
    """
    X = np.array(X_WC, dtype=float)
    if X.shape != (4, 4):
        raise ValueError(f"X_WC must be (4, 4), got {X.shape}")
    if spec.translation_mm == 0.0 and spec.rotation_deg == 0.0:
        return X
    direction = rng.standard_normal(3)
    axis = rng.standard_normal(3)
    t_C = spec.translation_mm / 1000.0 * direction / np.linalg.norm(direction)  # [m]
    R_CC = axis_angle_to_matrix(axis, np.radians(spec.rotation_deg))
    return np.asarray(X @ make_pose(R_CC, t_C))


def believed_pose(
    spec: CameraSpec, X_WC: FloatArray, X_WR: FloatArray, X_WF: FloatArray | None, rng: np.random.Generator
) -> FloatArray:
    """The pose the cell is told of a camera truly at X_WC (4, 4): its measured one when the scenario has it
    (``measured``: X_RC, or X_FC on the arm's flange, X_WF where the arm is now), else the true pose with its
    calibration error (:func:`perturb_pose`)."""
    if spec.measured is None:
        return perturb_pose(X_WC, spec.extrinsic_error, rng)
    if spec.mount == "eye_in_hand" and X_WF is not None:
        return np.asarray(X_WF @ spec.measured.X)
    return np.asarray(X_WR @ spec.measured.X)
