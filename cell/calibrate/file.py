"""The calibration file ``cell calibrate --out CAL.yaml`` writes and ``--calibration CAL.yaml`` reads: each camera's
measured pose as a scenario reads it (``cameras.<name>.measured``: X_RC, or X_FC on the flange) with its stated
residual (``calibration: {translation_mm, rotation_deg}``, the RMS of the covariance), and what it rests on."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from cell.calibrate import _opencv
from cell.calibrate.result import CameraCalibration
from cell.errors import UsageError
from cell.geometry import FloatArray, matrix_to_rpy
from cell.scenario import CalibrationSpec, DistortionSpec, PoseSpec, Scenario

FORMAT = "cell-calibration/1"


def _pose(X: FloatArray) -> dict[str, list[float]]:
    rpy = np.degrees(matrix_to_rpy(X[:3, :3]))
    return {"xyz_m": [round(float(v), 7) for v in X[:3, 3]], "rpy_deg": [round(float(v), 6) for v in rpy]}


def _error(err: tuple[float, float] | None) -> dict[str, float] | None:
    if err is None:
        return None
    return {"translation_mm": round(err[0] * 1e3, 4), "rotation_deg": round(float(np.degrees(err[1])), 5)}


def camera_entry(cal: CameraCalibration) -> dict[str, Any]:
    """One camera's block of the file."""
    s, ic = cal.solution, cal.intrinsics
    entry: dict[str, Any] = {
        "mount": "fixed" if cal.frame == "robot_base" else "eye_in_hand",
        "frame": cal.frame,
        "measured": _pose(cal.X_AC),
        "calibration": {
            "translation_mm": round(s.sigma_translation_m * 1e3, 4),
            "rotation_deg": round(float(np.degrees(s.sigma_rotation_rad)), 5),
        },
        "poses": cal.poses,
        "reprojection_px": round(s.rms_px, 4),
        "held_out": {
            "images": cal.held_out_images,
            "reprojection_px": round(cal.held_out_px, 4),
            "residual_3d_mm": round(cal.held_out_3d_m * 1e3, 4),
        },
        "rotation_spread_deg": [round(v, 2) for v in cal.spread_deg],
        "intrinsics": {
            "fx_px": round(ic.fx, 3),
            "fy_px": round(ic.fy, 3),
            "cx_px": round(ic.cx, 3),
            "cy_px": round(ic.cy, 3),
            "sigma_px": [round(v, 3) for v in ic.sigma_px],
            "depth_scale": round(ic.depth_scale, 5),
            "depth_scale_sigma": round(ic.depth_scale_sigma, 5),
            "distortion": [round(v, 6) for v in ic.distortion],  # k1, k2, p1, p2, k3 measured
            "distortion_sigma": [round(v, 6) for v in ic.distortion_sigma],
            "distortion_shift_px": round(ic.distortion_shift_px, 3),  # the image's corner against the stated lens
            "distortion_shift_sigma_px": round(ic.distortion_shift_sigma_px, 3),
            "lens": [round(v, 6) for v in ic.lens],  # the model runs are told: the measured where flagged
            "flags": [str(f) for f in ic.flags],
        },
        "opencv": {name: {"measured": _pose(X)} for name, X in cal.opencv.items()},
    }
    if cal.dropped:
        entry["poses_dropped"] = {k: int(v) for k, v in cal.dropped.items()}
    if cal.X_AC_true is not None:
        entry["truth_error"] = _error(cal.truth_error())
        for name, X in cal.opencv.items():
            entry["opencv"][name]["truth_error"] = _error(cal.truth_error(X))
    return entry


def document(cals: Sequence[CameraCalibration], *, scenario: str, board: Mapping[str, Any]) -> dict[str, Any]:
    """The whole file as a mapping (YAML-ready)."""
    return {
        "format": FORMAT,
        "scenario": scenario,
        "opencv": _opencv.VERSION,
        "board": dict(board),
        "cameras": {c.camera: camera_entry(c) for c in cals},
    }


def read(path: Path) -> dict[str, Any]:
    """The calibration file at ``path``; UsageError (the command line's input) when it is not one."""
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as e:
        raise UsageError(f"--calibration {str(path)!r}: cannot read it ({e})") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT or not isinstance(doc.get("cameras"), dict):
        raise UsageError(f"--calibration {str(path)!r} is not a calibration file (format: {FORMAT}; cell calibrate)")
    return doc


def flagged(doc: Mapping[str, Any]) -> dict[str, list[str]]:
    """Camera -> what its calibration flagged (``intrinsics.flags``: focal, principal_point, depth_scale)."""
    out = {}
    for name, entry in doc["cameras"].items():
        flags = (entry.get("intrinsics") or {}).get("flags") or []
        if flags:
            out[str(name)] = [str(f) for f in flags]
    return out


def apply(scn: Scenario, doc: Mapping[str, Any], source: str = "--calibration") -> Scenario:
    """The scenario with each calibrated camera's measured pose and stated residual in place of its own, and the
    lens model the calibration concluded (``intrinsics.lens``) as the one the cell is told."""
    cameras = dict(scn.cameras)
    for name, entry in doc["cameras"].items():
        if name not in cameras:
            raise UsageError(
                f"{source}: camera {name!r} is not in scenario {scn.name!r}; cameras: {', '.join(cameras)}"
            )
        cam = cameras[name]
        mount = "fixed" if entry.get("frame") == "robot_base" else "eye_in_hand"
        if cam.mount != mount:
            raise UsageError(f"{source}: camera {name!r} was calibrated as {mount}, the scenario mounts it {cam.mount}")
        try:
            measured = PoseSpec(**entry["measured"])
            stated = CalibrationSpec(**entry["calibration"])
        except (TypeError, KeyError, ValueError) as e:
            raise UsageError(f"{source}: camera {name!r}: {' '.join(str(e).split())}") from None
        update: dict[str, Any] = {"measured": measured, "calibration": stated}
        lens = (entry.get("intrinsics") or {}).get("lens")
        if lens is not None:
            try:
                update["measured_distortion"] = DistortionSpec(
                    **dict(zip(("k1", "k2", "p1", "p2", "k3"), lens, strict=True))
                )
            except (TypeError, ValueError):
                raise UsageError(
                    f"{source}: camera {name!r}: intrinsics.lens is {lens!r}; valid: five numbers k1, k2, p1, p2, k3"
                ) from None
        cameras[name] = cam.model_copy(update=update)
    return scn.model_copy(update={"cameras": cameras})
