"""Generate the round-part weldment maps: ``maps/pipe_flange.dxf``, ``maps/pipe_stub.dxf``, ``maps/post_plate.dxf``,
``maps/railing.dxf``, ``maps/round_brace.dxf`` and ``maps/tube_tee.dxf`` (tubes tessellated as MESH bodies, their
curved seams as CIRCLE, ELLIPSE and SPLINE).

Run from the repository root::

    .venv/bin/python tools/make_round.py            # writes the six maps into maps/
    .venv/bin/python tools/make_round.py --out DIR  # somewhere else

Millimetres, map frame M with z = 0 on the table top (docs/scenarios.md lists the scenarios that use them):

- ``pipe_flange``: a 219.1 x 8.2 pipe 350 mm tall standing on a 400 x 400 x 20 flange plate, four 8 mm gussets
  (80 x 150, a 15 mm snipe where the pipe's fillet runs under them) standing on the plate against the pipe's sides;
  the pipe's fillet is a CIRCLE (a T, cylinder on plane), the gussets' fillets are LINEs (16);
- ``pipe_stub``: the same pipe 250 mm tall on a 360 x 360 x 20 flange plate, no gussets: its fillet a CIRCLE alone,
  welded all round on a positioner (a shop welds it before any gusset goes on);
- ``post_plate``: a 60 x 4 post 80 mm tall (48 facets) on a 200 x 200 x 10 base plate: its fillet a CIRCLE alone
  (the ``track-post`` scenario, welded from a linear track);
- ``railing``: two 48.3 x 3.2 posts between a flat-bar bottom rail (lying on the table) and a flat-bar top rail
  (60 x 10) 600 mm above it, three 40 x 10 x 250 flat balusters standing on the bottom rail; the posts' four
  fillets are CIRCLEs (those under the top rail overhead), the balusters' six are LINEs;
- ``round_brace``: an 80 x 80 x 350 post on a 500 x 300 x 15 base plate, and a 42.4 x 3.2 round brace leaning 35
  degrees from the plate to the post's -x face, both ends cut flat: the brace's fillets are ELLIPSEs (on the plate, and
  in the post's vertical face: an OCS along -x); the post's four fillets are LINEs;
- ``tube_tee``: a 114.3 x 6 run pipe between two 250 x 250 x 15 end plates standing on the table, a 60.3 x 4 branch
  coped onto its top (the saddle: a SPLINE through the true curve), a 50 x 10 tie bar on the table between the
  plates beside the pipe; the run's fillets are CIRCLEs in the plates' planes (OCS along +-x), the tie's two are
  LINEs (``tube-tee``; ``tube-tee-positioner`` clamps it on a positioner).

Every seam is red (BYLAYER) on layer ``WELD_SEAMS`` with its id as XDATA (``WELDCELL``). Byte-stable output.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path

import ezdxf
import numpy as np
from make_maps import PART_LAYER_COLOR, REPO_ROOT, SEAM_LAYER_COLOR, _add_seam, box_mesh, write_stable
from round_meshes import (
    add_circle_seam,
    add_spline_seam,
    add_tube_on_plane_seam,
    plane_cut,
    pose,
    prism_mesh,
    rot_y,
    rot_z,
    saddle_points,
    tube_mesh,
)

SEAM_LAYER = "WELD_SEAMS"
Vec = tuple[float, float, float]


class _Map:
    """A drawing being built: MESH bodies on layers named after them, seams on WELD_SEAMS."""

    def __init__(self) -> None:
        self.doc = ezdxf.new("R2018", units=4)
        self.doc.appids.add("WELDCELL")
        self.doc.layers.add(SEAM_LAYER, color=SEAM_LAYER_COLOR)
        self.msp = self.doc.modelspace()
        self.lines = 0

    def body(self, name: str, mesh: ezdxf.render.MeshTransformer) -> None:
        self.doc.layers.add(name, color=PART_LAYER_COLOR)
        mesh.render_mesh(self.msp, dxfattribs={"layer": name, "color": 256})

    def line(self, seam_id: str, p0: Vec, p1: Vec) -> None:
        _add_seam(self.msp, seam_id, p0, p1, SEAM_LAYER, "bylayer", None)
        self.lines += 1


def _flat(z0: float, z1: float) -> tuple[Callable[[float, float], float], Callable[[float, float], float]]:
    return (lambda x, y: z0), (lambda x, y: z1)


def build_pipe_flange() -> ezdxf.document.Drawing:
    m = _Map()
    R, wall, H, T, n = 109.55, 8.2, 350.0, 20.0, 64
    m.body("FLANGE", box_mesh((-200.0, -200.0, 0.0), (200.0, 200.0, T)))
    m.body("PIPE", tube_mesh(R, R - wall, n, *_flat(T, T + H), np.eye(4)))
    add_circle_seam(m.msp, "PIPE>FLANGE:circle", (0.0, 0.0, T), R, (0.0, 0.0, 1.0), SEAM_LAYER)
    ra = R * math.cos(math.pi / n)  # a facet's distance from the axis: the gusset stands flat on it
    w, h, snipe, t = 80.0, 150.0, 15.0, 8.0
    profile = [(ra, T + snipe), (ra + snipe, T), (ra + w, T), (ra + w, T + 15.0), (ra, T + h)]
    for k, deg in enumerate((0.0, 90.0, 180.0, 270.0)):
        name = f"GUSSET_{k + 1}"
        Rz = rot_z(deg)
        m.body(name, prism_mesh(profile, t, pose(Rz, (0.0, 0.0, 0.0))))
        for side, y in (("-", -t / 2.0), ("+", t / 2.0)):

            def at(x: float, z: float, y: float = y, Rz: np.ndarray = Rz) -> Vec:
                p = Rz @ np.array([x, y, z])
                return (float(p[0]), float(p[1]), float(p[2]))

            m.line(f"{name}>FLANGE:{side}", at(ra + snipe, T), at(ra + w, T))
            m.line(f"{name}>PIPE:{side}", at(ra, T + snipe), at(ra, T + h))
    return m.doc


def build_pipe_stub() -> ezdxf.document.Drawing:
    m = _Map()
    R, wall, H, T = 109.55, 8.2, 250.0, 20.0  # a DN 200 pipe stub on a square flange plate, no gussets
    m.body("FLANGE", box_mesh((-180.0, -180.0, 0.0), (180.0, 180.0, T)))
    m.body("PIPE", tube_mesh(R, R - wall, 128, *_flat(T, T + H), np.eye(4)))  # 0.03 mm sagitta: a fine export
    add_circle_seam(m.msp, "PIPE>FLANGE:circle", (0.0, 0.0, T), R, (0.0, 0.0, 1.0), SEAM_LAYER)
    return m.doc


def build_post_plate() -> ezdxf.document.Drawing:
    m = _Map()
    R, wall, H, T = 30.0, 4.0, 80.0, 10.0  # a 60 mm post standing on a small base plate (welded on a track)
    m.body("PLATE", box_mesh((-100.0, -100.0, 0.0), (100.0, 100.0, T)))
    m.body("POST", tube_mesh(R, R - wall, 48, *_flat(T, T + H), np.eye(4)))
    add_circle_seam(m.msp, "POST>PLATE:circle", (0.0, 0.0, T), R, (0.0, 0.0, 1.0), SEAM_LAYER)
    return m.doc


def build_railing() -> ezdxf.document.Drawing:
    m = _Map()
    L, bw, bt, H = 1200.0, 60.0, 10.0, 600.0  # rails: length, width, thickness; posts' height between the rails
    m.body("BOTTOM_RAIL", box_mesh((-L / 2, -bw / 2, 0.0), (L / 2, bw / 2, bt)))
    m.body("TOP_RAIL", box_mesh((-L / 2, -bw / 2, bt + H), (L / 2, bw / 2, 2 * bt + H)))
    R, wall = 24.15, 3.2
    for k, x in enumerate((-500.0, 500.0)):
        name = f"POST_{'LR'[k]}"
        m.body(name, tube_mesh(R, R - wall, 48, *_flat(bt, bt + H), pose(np.eye(3), (x, 0.0, 0.0))))
        add_circle_seam(m.msp, f"{name}>BOTTOM_RAIL:circle", (x, 0.0, bt), R, (0.0, 0.0, 1.0), SEAM_LAYER)
        add_circle_seam(m.msp, f"{name}>TOP_RAIL:circle", (x, 0.0, bt + H), R, (0.0, 0.0, -1.0), SEAM_LAYER)
    a, b, h = 20.0, 5.0, 250.0  # a baluster's half width (along x), half thickness (along y), height
    for k, x in enumerate((-250.0, 0.0, 250.0)):
        name = f"BALUSTER_{k + 1}"
        m.body(name, box_mesh((x - a, -b, bt), (x + a, b, bt + h)))
        for side, y in (("-y", -b), ("+y", b)):
            m.line(f"{name}>BOTTOM_RAIL:{side}", (x - a, y, bt), (x + a, y, bt))
    return m.doc


def build_round_brace() -> ezdxf.document.Drawing:
    m = _Map()
    T = 15.0
    m.body("BASE", box_mesh((-250.0, -150.0, 0.0), (250.0, 150.0, T)))
    post = ((100.0, -40.0, T), (180.0, 40.0, T + 350.0))
    m.body("POST", box_mesh(*post))
    (x0, y0, z0), (x1, y1, _) = post
    m.line("POST>BASE:-x", (x0, y0, z0), (x0, y1, z0))
    m.line("POST>BASE:+x", (x1, y0, z0), (x1, y1, z0))
    m.line("POST>BASE:-y", (x0, y0, z0), (x1, y0, z0))
    m.line("POST>BASE:+y", (x0, y1, z0), (x1, y1, z0))
    R, wall, lean = 21.2, 3.2, 35.0
    foot = np.array([-60.0, 0.0, T])  # the axis meets the plate here
    X = pose(rot_y(lean), foot)  # the brace's axis leans towards +x
    axis = X[:3, 2]
    s = (x0 - foot[0]) / axis[0]  # the axis meets the post's -x face
    top = foot + s * axis
    m.body("BRACE", tube_mesh(R, R - wall, 48, plane_cut(X, (0, 0, 1), T), plane_cut(X, (1, 0, 0), x0), X))
    add_tube_on_plane_seam(m.msp, "BRACE>BASE:ellipse", foot, axis, R, (0.0, 0.0, 1.0), SEAM_LAYER)
    add_tube_on_plane_seam(m.msp, "BRACE>POST:ellipse", top, axis, R, (-1.0, 0.0, 0.0), SEAM_LAYER)
    return m.doc


def build_tube_tee() -> ezdxf.document.Drawing:
    m = _Map()
    Rr, wr, zc, half, P = 57.15, 6.0, 150.0, 300.0, 15.0  # run radius, wall, axis height, half length, plate
    m.body("END_L", box_mesh((-half - P, -125.0, 0.0), (-half, 125.0, 250.0)))
    m.body("END_R", box_mesh((half, -125.0, 0.0), (half + P, 125.0, 250.0)))
    X_run = pose(rot_y(90.0), (0.0, 0.0, zc))  # the run's axis (tube z) along map +x
    m.body("RUN", tube_mesh(Rr, Rr - wr, 64, *_flat(-half, half), X_run))
    add_circle_seam(m.msp, "RUN>END_L:circle", (-half, 0.0, zc), Rr, (1.0, 0.0, 0.0), SEAM_LAYER)
    add_circle_seam(m.msp, "RUN>END_R:circle", (half, 0.0, zc), Rr, (-1.0, 0.0, 0.0), SEAM_LAYER)
    Rb, wb = 30.15, 4.0

    def cope(x: float, y: float) -> float:
        return zc + math.sqrt(Rr**2 - y**2)

    m.body("BRANCH", tube_mesh(Rb, Rb - wb, 48, cope, lambda x, y: zc + 250.0, np.eye(4)))
    add_spline_seam(m.msp, "BRANCH>RUN:saddle", saddle_points(0.0, Rb, zc, Rr), SEAM_LAYER)
    y0, y1 = 65.0, 115.0  # the tie runs beside the pipe, not under it, so its fillets are in sight
    m.body("TIE", box_mesh((-half, y0, 0.0), (half, y1, 10.0)))
    m.line("TIE>END_L:+z", (-half, y0, 10.0), (-half, y1, 10.0))
    m.line("TIE>END_R:+z", (half, y0, 10.0), (half, y1, 10.0))
    return m.doc


MAPS: dict[str, Callable[[], ezdxf.document.Drawing]] = {
    "pipe_flange": build_pipe_flange,
    "pipe_stub": build_pipe_stub,
    "post_plate": build_post_plate,
    "railing": build_railing,
    "round_brace": build_round_brace,
    "tube_tee": build_tube_tee,
}


def main(argv: Sequence[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--out", type=Path, default=REPO_ROOT / "maps", help="output folder (default: maps/)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, build in MAPS.items():
        path = write_stable(build, args.out / f"{name}.dxf")
        print(f"{path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
