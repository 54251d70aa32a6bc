"""Scenario YAML read as strictly as it is used: a key given twice in one mapping is refused (YAML keeps the last one
silently), ``1e-3`` is a number as YAML 1.2 reads it (PyYAML's YAML 1.1 reads it as text), and any number beyond
:data:`ABSURD` is refused before the models see it (a camera at 1e300 m would pass every range and fail in IK)."""

from __future__ import annotations

import math
import re
from typing import Any

import yaml

from cell.errors import ScenarioError

# No number of a scenario (metres, millimetres, degrees, seconds, counts) is this large; ``seed`` is not bounded.
ABSURD = 1e6
_UNBOUNDED = {("seed",)}
_FLOAT_12 = re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$")


class DuplicateKeyError(yaml.YAMLError):
    """A mapping names one key twice: ``key``, and the 1-based lines of its first and second occurrence."""

    def __init__(self, key: str, first: int, second: int) -> None:
        super().__init__(f"key {key!r} given twice")
        self.key, self.first, self.second = key, first, second


class _Loader(yaml.CSafeLoader):
    """PyYAML's safe loader on libyaml's parser (the pure-Python one reads a scenario several times slower), which
    refuses a key given twice and reads YAML 1.2 floats."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue
            try:
                key = self.construct_object(key_node, deep=True)
                hash(key)
            except (TypeError, yaml.YAMLError):
                continue  # SafeLoader's own error says what is wrong with the key
            line = key_node.start_mark.line + 1
            if key in seen:
                raise DuplicateKeyError(str(key), seen[key], line)
            seen[key] = line
        return super().construct_mapping(node, deep=deep)


_Loader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT_12, list("-+0123456789"))


def parse(text: str, source: str) -> Any:
    """The YAML text as Python values; ScenarioError (one line, with the line number) when it is not YAML or names
    a key twice."""
    try:
        return yaml.load(text, Loader=_Loader)
    except DuplicateKeyError as err:
        raise ScenarioError(
            f"{source}: key {err.key!r} is given twice in one mapping (lines {err.first} and {err.second}); "
            "give each key once"
        ) from None
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise ScenarioError(f"{source}: not valid YAML{where}: {getattr(err, 'problem', err)}") from None


def frozen(data: Any, source: str, path: tuple[str, ...] = ()) -> Any:
    """``data`` with every list a tuple (the models validate strictly: a tuple field takes a tuple), after refusing
    any number that is absurd (beyond :data:`ABSURD`) or not finite."""
    if isinstance(data, dict):
        return {k: frozen(v, source, (*path, str(k))) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return tuple(frozen(v, source, (*path, str(i))) for i, v in enumerate(data))
    if isinstance(data, (int, float)) and not isinstance(data, bool) and path not in _UNBOUNDED:
        where = ".".join(path) or "<top level>"
        if not math.isfinite(data):
            raise ScenarioError(f"{source}: {where}: {data} is not a finite number; give a number")
        if abs(data) > ABSURD:
            raise ScenarioError(
                f"{source}: {where}: {data:g} is absurd; a scenario's numbers (metres, millimetres, degrees) lie "
                f"within +-{ABSURD:g}"
            )
    return data
