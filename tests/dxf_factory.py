"""Helpers for tests that need DXF welding maps: the generator in tools/ made importable, and bad files."""

from __future__ import annotations

import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
for _p in (REPO_ROOT, REPO_ROOT / "tools"):
    if str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

import make_brace  # noqa: E402, F401  (after the path set-up above; the tests import it from here)
import make_maps  # noqa: E402

BoxSpec = make_maps.BoxSpec
SeamSpec = make_maps.SeamSpec


def design(name: str) -> tuple[dict[str, BoxSpec], list[SeamSpec]]:
    """Parts and seams [mm] of one of the shipped maps (``fence1``, ``fence2``, ``ladder``)."""
    parts, junctions = make_maps.designs()[name]
    return dict(parts), make_maps.all_seams(parts, junctions)


def scaled(
    parts: dict[str, BoxSpec], seams: list[SeamSpec], factor: float
) -> tuple[dict[str, BoxSpec], list[SeamSpec]]:
    """The same design with every coordinate multiplied by ``factor`` (to draw it in other units)."""

    def s(p: tuple[float, float, float]) -> tuple[float, float, float]:
        return (p[0] * factor, p[1] * factor, p[2] * factor)

    return (
        {n: (s(lo), s(hi)) for n, (lo, hi) in parts.items()},
        [(i, s(a), s(b)) for i, a, b in seams],
    )


def web_on_plate(path: Path, along: str, wall: bool = False) -> Path:
    """A 400 x 300 x 10 mm plate with a 300 x 10 x 100 mm web standing on it along ``along`` (x or y) and its two
    fillets (the web's long sides on the plate's top); ``wall``: a 300 x 20 x 200 mm block 60 mm beside the web's
    +y side (along x only)."""
    if along == "x":
        parts = {"PLATE": ((0.0, 0.0, 0.0), (400.0, 300.0, 10.0)), "WEB": ((50.0, 145.0, 10.0), (350.0, 155.0, 110.0))}
        sides = ("+y", "-y")
    else:
        parts = {"PLATE": ((0.0, 0.0, 0.0), (300.0, 400.0, 10.0)), "WEB": ((145.0, 50.0, 10.0), (155.0, 350.0, 110.0))}
        sides = ("+x", "-x")
    seams = [s for s in make_maps.junction_seams(parts, "WEB", "PLATE") if s[0].rsplit(":", 1)[1] in sides]
    if wall:
        parts["WALL"] = ((50.0, 215.0, 10.0), (350.0, 235.0, 210.0))
    return make_maps.write_map(path, parts, seams)
