"""Ranges of option values, declared once on the field: ``Annotated[float, Bounds(ge=0.0, le=1.0)]``.

An options class calls :func:`check_bounds` from its ``__post_init__``, so a value out of range is refused where the
options are made (in code, or by the scenario loader, which reports the key); ``tools/scenario_docs.py`` reads the
same bounds (``ge``, ``gt``, ``le``, ``lt``) into the range column of ``docs/scenarios.md``.
"""

from __future__ import annotations

import dataclasses
import operator
import typing
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

_TESTS: tuple[tuple[str, Callable[[Any, Any], bool], str], ...] = (
    ("ge", operator.ge, ">="),
    ("gt", operator.gt, ">"),
    ("le", operator.le, "<="),
    ("lt", operator.lt, "<"),
)


@dataclass(frozen=True)
class Bounds:
    """Inclusive (``ge``, ``le``) or strict (``gt``, ``lt``) limits of a number, or of each number of a tuple."""

    ge: float | None = None
    gt: float | None = None
    le: float | None = None
    lt: float | None = None

    def violation(self, value: float) -> str:
        """'' when ``value`` is inside, else what it must be (``must be > 0``)."""
        for attr, test, sign in _TESTS:
            limit = getattr(self, attr)
            if limit is not None and not test(value, limit):
                return f"must be {sign} {limit:g}"
        return ""


def _values(value: Any) -> Iterable[Any]:
    return value if isinstance(value, tuple) else (value,)


_BOUNDED: dict[type, tuple[tuple[str, Bounds], ...]] = {}


def _bounded_fields(cls: type) -> tuple[tuple[str, Bounds], ...]:
    """(field name, bounds) of a dataclass's fields annotated with :class:`Bounds` (read once per class)."""
    if cls not in _BOUNDED:
        hints = typing.get_type_hints(cls, include_extras=True)
        _BOUNDED[cls] = tuple(
            (f.name, b)
            for f in dataclasses.fields(cls)
            for b in getattr(hints.get(f.name), "__metadata__", ())
            if isinstance(b, Bounds)
        )
    return _BOUNDED[cls]


def check_bounds(options: Any) -> None:
    """ValueError naming the first field of the dataclass ``options`` whose value is outside its :class:`Bounds`."""
    for name, bound in _bounded_fields(type(options)):
        for v in _values(getattr(options, name)):
            problem = bound.violation(v)
            if problem:
                raise ValueError(f"{name} {problem}, got {v!r}")
