"""Our straight locator where the receiving face is a flat facet of a round body (a gusset on a pipe drawn as a
64-gon): the facet recognised as the round's, its points' heights taken off the map's cylinder, and the region
beside the seam that holds them."""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import numpy as np
from dxf_factory import make_maps
from round_meshes import add_circle_seam, pose, tube_mesh

from cell.seams.ours._round import round_facet
from cell.types import Part, WeldMap
from cell.weldmap import read_map

R_MM, FACETS = 109.55, 64


def _pipe_map(tmp_path: Path) -> WeldMap:
    """A 219.1 mm pipe (64 facets, a facet facing +x) 350 mm tall on a 400 mm plate, its fillet drawn."""
    doc = ezdxf.new("R2018", units=4)
    msp = doc.modelspace()
    doc.layers.add("WELD_SEAMS", color=1)
    make_maps.box_mesh((-200, -200, 0), (200, 200, 20)).render_mesh(msp, dxfattribs={"layer": "PLATE"})
    tube_mesh(R_MM, R_MM - 8.2, FACETS, lambda x, y: 20.0, lambda x, y: 370.0, pose(np.eye(3), (0, 0, 0))).render_mesh(
        msp, dxfattribs={"layer": "PIPE"}
    )
    add_circle_seam(msp, "PIPE>PLATE", (0.0, 0.0, 20.0), R_MM, (0.0, 0.0, 1.0), "WELD_SEAMS")
    path = tmp_path / "pipe.dxf"
    doc.saveas(path)
    return read_map(path)


def _facet_towards(part: Part, direction: np.ndarray) -> str:
    """The name of ``part``'s face whose outward normal is nearest ``direction`` (3,)."""
    return max(part.face_names(), key=lambda f: float(part.face_plane(f)[0] @ direction))


def test_a_facet_along_the_axis_is_the_rounds_and_its_points_heights_are_off_the_round(tmp_path: Path) -> None:
    wm = _pipe_map(tmp_path)
    pipe, plate = wm.part("PIPE"), wm.part("PLATE")
    assert pipe.cylinder is not None and pipe.cylinder.facets == FACETS
    c = pipe.cylinder
    # The facet whose normal is nearest +x: the seam of a gusset's side 4 mm off its middle, along the axis.
    face = _facet_towards(pipe, np.array([1.0, 0.0, 0.0]))
    n, d = pipe.face_plane(face)
    side = np.cross(c.axis, n)
    p0 = c.p_base + (d - float(n @ c.p_base)) * n + 0.004 * side + 0.1 * c.axis
    rf = round_facet(pipe, face, p0, c.axis)
    assert rf is not None
    # Its sigma's share that no fit sees: half the 64 facets' sagitta (0.13 mm on this pipe).
    assert math.isclose(rf.bias_m, 0.5e-3 * R_MM * (1.0 - math.cos(math.pi / FACETS)), rel_tol=1e-3)
    # Not a facet's: a seam across the axis, or a plate's face.
    assert round_facet(pipe, face, p0, side) is None
    top = _facet_towards(plate, np.array([0.0, 0.0, 1.0]))
    assert round_facet(plate, top, p0, np.array([1.0, 0.0, 0.0])) is None
    # Points on the round (the seam line's distance from the axis plus h) up to 35 deg round from the facet's
    # middle: their residual off the facet's plane less the flattening is h, whatever their angle (the plane's own
    # residual grows to 17 mm there).
    ang = np.radians(np.linspace(-35.0, 35.0, 15))
    h = np.linspace(-0.001, 0.002, 15)
    radial = np.cos(ang)[:, None] * n + np.sin(ang)[:, None] * side
    P = c.p_base + 0.2 * c.axis + (rf.rho0 + h)[:, None] * radial
    plane = P @ n - d
    assert np.abs(plane).max() > 0.015
    np.testing.assert_allclose(plane - rf.flattening(P), h, atol=1e-9)
    # Over the round beside the seam: within the body's length (less the band) and 40 deg round; not beyond.
    assert rf.over(P, 0.004).all()
    far = (
        c.p_base
        + np.outer([0.002, 0.2, 0.2, 0.36], c.axis)
        + rf.rho0 * np.array([n, math.cos(math.radians(60.0)) * n + math.sin(math.radians(60.0)) * side, -n, n])
    )
    assert rf.over(far, 0.004).tolist() == [False, False, False, False]
