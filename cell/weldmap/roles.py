"""Which layers hold what: parts, fixtures (obstacles, never welded) and seams, by shell-style name patterns that,
like DXF layer names, ignore case (docs/maps.md section 3). No ezdxf here."""

from __future__ import annotations

import fnmatch
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal, Protocol

DEFAULT_FIXTURE_LAYERS: tuple[str, ...] = ("FIXTURE*", "CLAMP*", "JIG*", "STOP*")

Role = Literal["part", "fixture", "ignored"]


class LayerPatterns(Protocol):
    """What :func:`read_map` needs of a layer spec (the scenario's ``map.layers`` or :class:`LayerRoles`)."""

    @property
    def parts(self) -> Sequence[str] | None: ...
    @property
    def fixtures(self) -> Sequence[str]: ...
    @property
    def seams(self) -> Sequence[str]: ...


@dataclass(frozen=True)
class LayerRoles:
    """The default roles: every body a part unless on a fixture layer; seams by colour alone."""

    parts: tuple[str, ...] | None = None
    fixtures: tuple[str, ...] = DEFAULT_FIXTURE_LAYERS
    seams: tuple[str, ...] = ()


def matches(name: str, patterns: Sequence[str]) -> bool:
    """Whether ``name`` matches one of the shell-style ``patterns``, ignoring case."""
    up = name.upper()
    return any(fnmatch.fnmatchcase(up, p.upper()) for p in patterns)


def body_role(name: str, layer: str, spec: LayerPatterns) -> Role:
    """A body's role from its name (layer or block) and its layer."""
    if matches(name, spec.fixtures) or matches(layer, spec.fixtures):
        return "fixture"
    if spec.parts is None or matches(name, spec.parts) or matches(layer, spec.parts):
        return "part"
    return "ignored"
