"""Curved seams in the welding map: each entity kind read as its typed curve in the map frame (OCS not +z, INSERT
transforms, the bulge's sign), checked against ezdxf's own WCS answers; stable ids."""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from dxf_factory import make_maps
from ezdxf.math import Vec3

from cell.types import ArcCurve, EllipseCurve, SampledCurve, Unsupported
from cell.weldmap import read_map

PARTS = {
    "POST_L": ((200.0, 700.0, 0.0), (280.0, 780.0, 600.0)),
    "TOP_RAIL": ((280.0, 700.0, 520.0), (1120.0, 780.0, 600.0)),
}
M = 1e-3  # drawing units (mm) -> m


def _read(doc: ezdxf.document.Drawing, tmp_path: Path):  # type: ignore[no-untyped-def]
    path = tmp_path / "curves.dxf"
    doc.saveas(path)
    return read_map(path)


def _doc() -> ezdxf.document.Drawing:
    seams = [("POST_L>TOP_RAIL:+z", (280.0, 700.0, 600.0), (280.0, 780.0, 600.0))]
    return make_maps.build_map(PARTS, seams, solid="mesh")


def _near(points: np.ndarray, q: np.ndarray) -> float:
    return float(np.linalg.norm(points - q, axis=1).min())


def test_a_circle_in_a_plane_along_x_is_read_through_its_ocs(tmp_path: Path) -> None:
    doc = _doc()
    n = Vec3(1.0, 0.0, 0.0)  # drawn in a plane x = const: its OCS is not the WCS
    ocs = ezdxf.math.OCS(n)
    circle = doc.modelspace().add_circle(ocs.from_wcs(Vec3(280, 740, 560)), 30, dxfattribs={"color": 1, "extrusion": n})
    [c] = _read(doc, tmp_path).curved
    assert isinstance(c.curve, ArcCurve) and c.kind == "circle" and c.id == f"seam-{circle.dxf.handle}"
    np.testing.assert_allclose(c.curve.centre, [0.28, 0.74, 0.56], atol=1e-12)
    np.testing.assert_allclose(abs(c.curve.normal @ [1, 0, 0]), 1.0)
    p = c.sample(0.001)
    assert np.allclose(p[:, 0], 0.28) and np.allclose(np.linalg.norm(p - c.curve.centre, axis=1), 0.03)
    assert math.isclose(c.length, 2 * math.pi * 0.03, rel_tol=1e-12)
    ezdxf_points = np.array([tuple(v) for v in circle.vertices([0, 90, 180, 270])]) * M  # ezdxf's own WCS answer
    assert max(_near(c.sample(1e-5), q) for q in ezdxf_points) < 6e-6  # half the sampling step


def test_an_arc_drawn_from_below_keeps_its_ends_and_turn(tmp_path: Path) -> None:
    doc = _doc()
    arc = doc.modelspace().add_arc((-240, 740, -600), 40, 20, 160, dxfattribs={"color": 1, "extrusion": (0, 0, -1)})
    [c] = _read(doc, tmp_path).curved
    assert isinstance(c.curve, ArcCurve) and c.kind == "arc"
    assert math.isclose(c.curve.sweep_rad, math.radians(140.0), rel_tol=1e-12)
    p = c.sample(0.0005)
    np.testing.assert_allclose(p[0], np.array(arc.start_point) * M, atol=1e-12)  # ezdxf's start and end in WCS
    np.testing.assert_allclose(p[-1], np.array(arc.end_point) * M, atol=1e-12)
    mid = np.array(next(iter(arc.vertices([90.0])))) * M
    assert _near(c.sample(1e-5), mid) < 6e-6


def test_an_ellipse_is_read_with_its_axes_and_parameters(tmp_path: Path) -> None:
    doc = _doc()
    e = doc.modelspace().add_ellipse(
        (240, 740, 600), (0, 50, 0), 0.5, 0.3, 4.0, dxfattribs={"color": 1, "extrusion": (0, 0, -1)}
    )
    [c] = _read(doc, tmp_path).curved
    assert isinstance(c.curve, EllipseCurve) and c.kind == "ellipse"
    np.testing.assert_allclose(c.curve.major, [0, 0.05, 0], atol=1e-12)
    assert math.isclose(float(np.linalg.norm(c.curve.minor)), 0.025, rel_tol=1e-12)
    p = c.sample(0.0005)
    np.testing.assert_allclose(p[[0, -1]], np.array([e.start_point, e.end_point]) * M, atol=1e-12)


def test_a_spline_is_sampled_within_its_stated_chord_error(tmp_path: Path) -> None:
    doc = _doc()
    fit = [(200, 700, 600), (300, 760, 620), (500, 720, 640), (700, 780, 600)]
    doc.modelspace().add_spline(fit_points=fit, dxfattribs={"color": 1})
    [c] = _read(doc, tmp_path).curved
    assert isinstance(c.curve, SampledCurve) and c.kind == "curve" and not c.curve.closed
    assert 0 < c.curve.chord_error_m <= 1e-4
    exact = np.array(
        [tuple(p) for p in doc.modelspace().query("SPLINE")[0].construction_tool().points(np.linspace(0, 1, 101))]
    )
    d = [_near(c.sample(c.curve.chord_error_m), q * M) for q in exact]
    assert max(d) <= 2 * c.curve.chord_error_m


@pytest.mark.parametrize("bulge", [0.5, -0.5])
def test_a_bulge_turns_the_way_its_sign_says(tmp_path: Path, bulge: float) -> None:
    doc = _doc()
    lw = doc.modelspace().add_lwpolyline([(200, 740, bulge), (280, 740, 0)], format="xyb", dxfattribs={"color": 1})
    lw.dxf.elevation = 600.0
    lw.set_xdata("WELDCELL", [(1000, "CAP")])
    m = _read(doc, tmp_path)
    [c] = m.curved
    assert c.id == "CAP.1" and isinstance(c.curve, ArcCurve)
    p = c.sample(0.0005)
    np.testing.assert_allclose(p[[0, -1]], [[0.2, 0.74, 0.6], [0.28, 0.74, 0.6]], atol=1e-12)
    # A positive bulge turns counter-clockwise about +z: seen going from start to end, the arc bulges to the right.
    sagitta = bulge * 0.08 / 2.0
    assert _near(p, np.array([0.24, 0.74 - sagitta, 0.6])) < 1e-5
    assert m.not_welded[0].code is Unsupported.CURVED_NOT_LOCATED


def test_a_bulged_polyline_drawn_from_below_matches_ezdxfs_own_arc(tmp_path: Path) -> None:
    doc = _doc()
    lw = doc.modelspace().add_lwpolyline([(-200, 740, 0.3), (-280, 740, 0)], format="xyb", dxfattribs={"color": 1})
    lw.dxf.extrusion, lw.dxf.elevation = (0.0, 0.0, -1.0), -600.0
    [c] = _read(doc, tmp_path).curved
    [arc] = [v for v in lw.virtual_entities() if v.dxftype() == "ARC"]  # ezdxf's explosion into a WCS-aware ARC
    p = c.sample(0.0005)
    mid = 0.5 * (arc.dxf.start_angle + arc.dxf.end_angle + (360.0 if arc.dxf.end_angle < arc.dxf.start_angle else 0.0))
    assert _near(p, np.array(next(iter(arc.vertices([mid])))) * M) < 1e-5
    np.testing.assert_allclose(p[0], [0.2, 0.74, 0.6], atol=1e-12)


def test_curves_in_blocks_take_the_insert_transform(tmp_path: Path) -> None:
    doc = _doc()
    block = doc.blocks.new("RINGS")
    block.add_circle((0, 0, 0), 10, dxfattribs={"color": 0})  # BYBLOCK: red through the INSERT
    doc.modelspace().add_blockref(
        "RINGS", (240, 740, 600), dxfattribs={"color": 1, "xscale": 2, "yscale": 2, "zscale": 2, "rotation": 30}
    )
    doc.modelspace().add_blockref("RINGS", (600, 740, 600), dxfattribs={"color": 1, "xscale": 3, "yscale": 1})
    round_, squashed = _read(doc, tmp_path).curved
    assert isinstance(round_.curve, ArcCurve) and math.isclose(round_.curve.radius, 0.02, rel_tol=1e-12)
    np.testing.assert_allclose(round_.curve.centre, [0.24, 0.74, 0.6], atol=1e-12)
    assert isinstance(squashed.curve, EllipseCurve)  # a non-uniform scale makes the circle an ellipse
    np.testing.assert_allclose(
        sorted([np.linalg.norm(squashed.curve.major), np.linalg.norm(squashed.curve.minor)]), [0.01, 0.03]
    )
    assert round_.id != squashed.id and round_.id.startswith("seam-") and round_.id.count(".") == 1
