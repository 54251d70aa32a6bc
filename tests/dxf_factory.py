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
