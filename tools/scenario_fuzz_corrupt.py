"""The random half of tools/scenario_fuzz.py's nonsense: a value of the wrong type or a non-finite or absurd one, a
list of the wrong length, a misspelt or unknown key, a required key deleted, a key given twice, broken YAML. Each
returns what it did, its `marked` words being what ``cell scenario check``'s line must name."""

from __future__ import annotations

import copy
import re
from typing import Any

import numpy as np

Data = dict[str, Any]
# Dicts whose keys are names the user chooses (a camera, a part, a seam): renaming one is no nonsense.
FREE = {"cameras", "deviations", "occluders", "seam_leg_mm", "closeup_locator_options"}


def _leaves(node: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    if isinstance(node, dict):
        return [p for k, v in node.items() for p in _leaves(v, (*path, k))]
    if isinstance(node, list):
        return [p for i, v in enumerate(node) for p in _leaves(v, (*path, i))]
    return [path]


def _keys(node: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Paths of the keys a schema names (not a camera's or a part's name)."""
    if not isinstance(node, dict):
        return [p for i, v in enumerate(node) for p in _keys(v, (*path, i))] if isinstance(node, list) else []
    free = bool(path) and path[-1] in FREE
    own = [] if free else [(*path, k) for k in node]
    return own + [p for k, v in node.items() for p in _keys(v, (*path, k))]


def _at(d: Any, path: tuple[Any, ...]) -> Any:
    for k in path:
        d = d[k]
    return d


def _named(path: tuple[Any, ...]) -> str:
    """``cameras.cam_left.`eye_m`.0``: the path with its last key marked (the check's line must name it)."""
    keys = [i for i, k in enumerate(path) if isinstance(k, str)]
    return ".".join(f"`{k}`" if i == keys[-1] else str(k) for i, k in enumerate(path))


def _bad_value(old: Any, rng: np.random.Generator) -> Any:
    """A value no key of the scenario takes in place of ``old`` (a wrong type, or a non-finite or absurd number)."""
    if isinstance(old, bool):
        return str(rng.choice(["yes please", "1"])) if rng.random() < 0.5 else {"on": True}
    if isinstance(old, (int, float)):
        choices: list[Any] = [float("nan"), float("inf"), -float("inf"), 1e300, -1e300, f"{old}", "twelve", [old, old]]
        return choices[int(rng.integers(len(choices)))]
    if isinstance(old, str):
        return [1e300, {"text": old}, [old, old]][int(rng.integers(3))]
    return "garbage"


def corrupt_value(d: Data, rng: np.random.Generator) -> str:
    leaves = [p for p in _leaves(d) if p and p[0] not in ("name", "description")]
    path = leaves[int(rng.integers(len(leaves)))]
    parent, key = _at(d, path[:-1]), path[-1]
    new = _bad_value(parent[key], rng)
    parent[key] = new
    return f"{_named(path)} set to {new!r}"


def corrupt_shape(d: Data, rng: np.random.Generator) -> str:
    lists = [p for p in _leaves(d) if p and isinstance(p[-1], int)]
    path = lists[int(rng.integers(len(lists)))][:-1]
    seq = _at(d, path)
    if rng.random() < 0.5 or len(seq) < 2:
        seq.append(seq[-1])
        return f"{_named(path)} given one value too many"
    seq.pop()
    return f"{_named(path)} given one value too few"


def corrupt_key(d: Data, rng: np.random.Generator) -> str:
    keys = [p for p in _keys(d) if not isinstance(p[-1], int)]
    path = keys[int(rng.integers(len(keys)))]
    parent, key = _at(d, path[:-1]), str(path[-1])
    if rng.random() < 0.5 and len(key) > 3:  # misspelt: two letters swapped or one dropped
        i = int(rng.integers(len(key) - 1))
        wrong = key[:i] + key[i + 1] + key[i] + key[i + 2 :] if key[i] != key[i + 1] else key[:i] + key[i + 1 :]
        parent[wrong] = parent.pop(key)
        return f"key {'.'.join(map(str, path))} misspelt `{wrong}`"
    parent[f"{key}_extra"] = copy.deepcopy(parent[key])
    return f"unknown key `{key}_extra` beside {'.'.join(map(str, path))}"


def delete_required(d: Data, rng: np.random.Generator) -> str:
    required = [("seed",), ("map",), ("table",), ("cameras",), ("perception",), ("map", "file"), ("table", "size_m")]
    path = required[int(rng.integers(len(required)))]
    del _at(d, path[:-1])[path[-1]]
    return f"required key `{'.'.join(path)}` deleted"


def duplicate_key(text: str, rng: np.random.Generator) -> tuple[str, str]:
    """A key line given again just below itself, with another value (YAML keeps the last one silently)."""
    lines = text.splitlines()
    cands = [i for i, ln in enumerate(lines) if re.match(r"^\s*[A-Za-z_]+:\s*[^\s#{\[]", ln)]
    i = cands[int(rng.integers(len(cands)))]
    m = re.match(r"^(\s*)([A-Za-z_]+):", lines[i])
    assert m is not None
    lines.insert(i + 1, f"{m.group(1)}{m.group(2)}: 0")
    return "\n".join(lines) + "\n", f"key `{m.group(2)}` `given twice` (line {i + 1} and {i + 2})"


def broken_yaml(text: str, rng: np.random.Generator) -> tuple[str, str]:
    lines = text.splitlines()
    i = int(rng.integers(len(lines)))
    junk = ["  : [", "{{", "\tkey: tab", "- list: in a map", "x: [1, 2"][int(rng.integers(5))]
    lines.insert(i, junk)
    return "\n".join(lines) + "\n", f"line {i + 1} is not `YAML` ({junk!r})"
