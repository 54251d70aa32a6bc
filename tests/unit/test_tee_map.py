"""The welding map of the real scans' tee (maps/tee.dxf, written by tools/make_maps.py) holds the CAD sizes of
../shared/real-scans/README.md: two 2 in square tubes and the two fillets where the vertical tube's x walls meet
the horizontal tube's top face."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from tools_loader import REPO, load_tool

from cell.seams.joint import find_joints
from cell.weldmap import read_map

INCH = 0.0254


def test_the_tee_map_holds_the_cad_sizes() -> None:
    m = read_map(REPO / "maps" / "tee.dxf")
    assert m.units == "mm"
    h, v = m.part("H_TUBE").box, m.part("V_TUBE").box
    np.testing.assert_allclose(h.size, [10.25 * INCH, 2 * INCH, 2 * INCH], atol=1e-9)  # 260.35 mm long
    np.testing.assert_allclose(h.center, [(-3.0 + 7.25) / 2 * INCH, 0.0, 0.0], atol=1e-9)  # x -76.2 .. 184.15
    np.testing.assert_allclose(v.size, [2 * INCH, 2 * INCH, 8.5 * INCH], atol=1e-9)  # 215.9 mm tall
    np.testing.assert_allclose(v.center, [0.0, 0.0, (1.0 + 9.5) / 2 * INCH], atol=1e-9)  # z 25.4 .. 241.3
    assert sorted(s.id for s in m.seams) == ["V_TUBE>H_TUBE:+x", "V_TUBE>H_TUBE:-x"]
    for s in m.seams:
        sign = 1.0 if s.id.endswith("+x") else -1.0
        np.testing.assert_allclose(s.p_start, [sign * INCH, -INCH, INCH], atol=1e-9)
        np.testing.assert_allclose(s.p_end, [sign * INCH, INCH, INCH], atol=1e-9)  # 50.8 mm along y
    joints = find_joints(m)
    assert {(j.abutting, j.receiving, j.face_receiving) for j in joints.values()} == {("V_TUBE", "H_TUBE", "+z")}


def test_the_generator_writes_the_shipped_tee(tmp_path: Path) -> None:
    make_maps = load_tool("make_maps")
    parts, junctions = make_maps.designs()["tee"]
    path = make_maps.write_map(tmp_path / "tee.dxf", parts, make_maps.design_seams("tee", parts, junctions))
    assert path.read_bytes() == (REPO / "maps" / "tee.dxf").read_bytes()


def test_the_generator_writes_the_shipped_flat_tee(tmp_path: Path) -> None:
    make_maps = load_tool("make_maps")
    parts, junctions = make_maps.designs()["tee_flat"]
    path = make_maps.write_map(tmp_path / "tee_flat.dxf", parts, make_maps.design_seams("tee_flat", parts, junctions))
    assert path.read_bytes() == (REPO / "maps" / "tee_flat.dxf").read_bytes()
    m = read_map(path)
    assert sorted(s.id for s in m.seams) == ["LONG_TUBE>CROSS_TUBE:+y", "LONG_TUBE>CROSS_TUBE:-y"]
    for s in m.seams:  # vertical, where the long tube's side walls meet the cross tube's face
        np.testing.assert_allclose(s.p_start[:2], [0.3048, 0.0254 if s.id.endswith("+y") else -0.0254], atol=1e-9)
        np.testing.assert_allclose(s.p_end - s.p_start, [0.0, 0.0, 2 * INCH], atol=1e-9)
