"""A plate with a 40 x 40 mm post and two round pipes beside it, seen by three fixed cameras: the cell where a
splice without a prior moved exactly calibrated cameras by millimetres (round bodies leave directions free).

:func:`write_post_pipes` writes the map (DXF, mm: the plate and the post as boxes, the pipes as tessellated
cylinders drawn as MESH bodies; the post's four fillets to the plate as seams) and a scenario beside it: the
cameras placed exactly, each stated at ``calibration`` (translation mm, rotation deg), realistic noise, nothing
built or placed off its drawing.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import ezdxf
from dxf_factory import make_maps
from ezdxf.math import Matrix44
from ezdxf.render import MeshTransformer

PARTS = {"PLATE": ((0.0, 0.0, 0.0), (400.0, 300.0, 10.0)), "POST": ((180.0, 130.0, 10.0), (220.0, 170.0, 130.0))}
PIPE_RADIUS_MM = 30.0
PIPE_SEGMENTS = 32
STANDING = (300.0, 80.0, 10.0, 140.0)  # x, y of its axis, z of its ends [mm]: a pipe standing on the plate
LYING = (40.0, 360.0, 240.0)  # x of its ends, y of its axis [mm]: a pipe lying on the plate along x


def cylinder_mesh(radius_mm: float, length_mm: float, segments: int, M: Matrix44) -> MeshTransformer:
    """A closed cylinder along z from 0 to ``length_mm`` (``segments`` side quads, triangle-fan caps, outward
    normals) [mm], moved by ``M``."""
    mesh = MeshTransformer()
    angles = [2.0 * math.pi * i / segments for i in range(segments)]
    ring = [(radius_mm * math.cos(a), radius_mm * math.sin(a)) for a in angles]
    verts = [(x, y, 0.0) for x, y in ring] + [(x, y, length_mm) for x, y in ring]
    verts += [(0.0, 0.0, 0.0), (0.0, 0.0, length_mm)]
    mesh.vertices = [ezdxf.math.Vec3(v) for v in verts]
    n, cb, ct = segments, 2 * segments, 2 * segments + 1
    faces: list[Sequence[int]] = [(i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n)]
    faces += [(cb, (i + 1) % n, i) for i in range(n)] + [(ct, n + i, n + (i + 1) % n) for i in range(n)]
    mesh.faces = faces
    mesh.transform(M)
    return mesh


def build_post_pipes() -> ezdxf.document.Drawing:
    """The map: plate and post (boxes, the post's four fillets to the plate) and two pipes (MESH cylinders)."""
    doc = make_maps.build_map(PARTS, make_maps.all_seams(PARTS, (("POST", "PLATE"),)), solid="mesh")
    msp = doc.modelspace()
    x, y, z0, z1 = STANDING
    x0, x1, y_lying = LYING
    pipes = {
        "PIPE_A": cylinder_mesh(PIPE_RADIUS_MM, z1 - z0, PIPE_SEGMENTS, Matrix44.translate(x, y, z0)),
        "PIPE_B": cylinder_mesh(
            PIPE_RADIUS_MM,
            x1 - x0,
            PIPE_SEGMENTS,
            Matrix44.y_rotate(math.pi / 2) @ Matrix44.translate(x0, y_lying, 10.0 + PIPE_RADIUS_MM),
        ),
    }
    for name, mesh in pipes.items():
        doc.layers.add(name, color=make_maps.PART_LAYER_COLOR)
        make_maps._add_body(msp, mesh, name, "mesh")
    return doc


_CAMERA = """  {name}:
    eye_m: [{x:.4f}, {y:.4f}, {z:.4f}]
    target_m: [0.15, 0.0, 0.95]
    calibration: {{translation_mm: {t}, rotation_deg: {r}}}
"""


def write_post_pipes(folder: Path, calibration: tuple[float, float] = (1.0, 0.1), seed: int = 3) -> Path:
    """Write ``post_pipes.dxf`` and ``post_pipes.yaml`` into ``folder``; returns the scenario's path. Three fixed
    cameras 1.3 m from the part at 50 deg elevation, 120 deg apart, placed exactly (``calibration`` stated)."""
    folder.mkdir(parents=True, exist_ok=True)
    build_post_pipes().saveas(folder / "post_pipes.dxf")
    cameras = ""
    for k, azimuth in enumerate((-30.0, 90.0, 210.0)):
        a, e = math.radians(azimuth), math.radians(50.0)
        eye = (0.15 + 1.3 * math.cos(e) * math.cos(a), 1.3 * math.cos(e) * math.sin(a), 0.95 + 1.3 * math.sin(e))
        cameras += _CAMERA.format(name=f"cam_{k}", x=eye[0], y=eye[1], z=eye[2], t=calibration[0], r=calibration[1])
    text = f"""name: post-pipes
description: a plate with a square post and two round pipes, three exactly placed cameras.
seed: {seed}
map:
  file: post_pipes.dxf
  X_WM: {{xyz_m: [-0.05, -0.15, 0.90]}}
table:
  center_m: [0.15, 0.0, 0.85]
  size_m: [2.0, 1.2, 0.10]
robot:
  urdf: kr5_arc.urdf
  X_WR: {{xyz_m: [0.15, -1.05, 0.90]}}
  home_deg: [-90.0, -100.0, 100.0, 0.0, 45.0, 0.0]
cameras:
{cameras}perception:
  workspace: {{min_m: [-0.30, -0.30, 0.905], max_m: [0.60, 0.30, 1.20]}}
simulation:
  noise: realistic
"""
    path = folder / "post_pipes.yaml"
    path.write_text(text)
    return path
