"""Loading scenarios: a name or a path -> YAML -> a validated :class:`Scenario`, or one ScenarioError line that
names the key and what is valid there."""

from __future__ import annotations

import dataclasses
import difflib
import types
from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, Literal, Union, get_args, get_origin, get_type_hints

from pydantic import BaseModel, ValidationError

from cell.errors import ScenarioError
from cell.scenario.model import Scenario
from cell.scenario.procedure_specs import with_procedures_file
from cell.scenario.yaml_text import frozen, parse

REPO_ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO_DIR = REPO_ROOT / "scenarios"
_UNKNOWN_KEY = ("extra_forbidden", "unexpected_keyword_argument")
_NUMBER_TYPES = ("int_type", "float_type", "int_from_float", "bool_type")


def _members(tp: Any) -> list[Any]:
    """The concrete types an annotation may hold: ``Annotated[X, ...]`` -> X, ``A | B | None`` -> A, B."""
    if get_origin(tp) is Annotated:
        return _members(get_args(tp)[0])
    if get_origin(tp) in (Union, types.UnionType):
        return [m for a in get_args(tp) if a is not type(None) for m in _members(a)]
    return [tp]


def _keys(tp: Any) -> dict[str, Any] | None:
    """Key -> annotation of a scenario model or an options dataclass; None for anything else."""
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        return {k: f.annotation for k, f in tp.model_fields.items() if not f.exclude}
    if isinstance(tp, type) and dataclasses.is_dataclass(tp):
        hints = get_type_hints(tp, include_extras=True)
        return {f.name: hints[f.name] for f in dataclasses.fields(tp)}
    return None


def _tag(tp: Any) -> str | None:
    """The ``method`` a member of a discriminated union is told by (pydantic puts it in the error's loc)."""
    keys = _keys(tp)
    method = keys.get("method") if keys else None
    values = get_args(method) if get_origin(method) is Literal else ()
    return str(values[0]) if len(values) == 1 else None


def _walk(model: type[BaseModel], loc: tuple[int | str, ...]) -> tuple[list[str], str]:
    """(keys valid at ``loc``, the location of an unknown key; ``loc`` as written in the file), by walking the
    models and options dataclasses. pydantic puts the chosen member's tag in a discriminated union's loc
    (``locator.ours.options``): the file has no such key, so the path leaves it out."""
    current: list[Any] = [model]
    path: list[str] = []
    for i, part in enumerate(loc):
        step: list[Any] = []
        tag = False
        for tp in (m for c in current for m in _members(c)):
            origin, keys = get_origin(tp), _keys(tp)
            if origin in (dict, Mapping):  # a free key (a camera or part name)
                step.append(get_args(tp)[1])
            elif origin in (tuple, list) and isinstance(part, int):
                step.extend(a for a in get_args(tp) if a is not Ellipsis)
            elif keys is not None and part in keys:
                step.append(keys[str(part)])
            elif _tag(tp) == part:  # the member of a discriminated union that was chosen
                step.append(tp)
                tag = True
        if not tag:
            path.append(str(part))
        if i < len(loc) - 1:
            current = step
    for tp in (m for c in current for m in _members(c)):
        keys = _keys(tp)
        if keys is not None:
            return list(keys), ".".join(path) or "<top level>"
    return [], ".".join(path) or "<top level>"


def _explain(err: ValidationError, source: str) -> str:
    errors = err.errors()
    # An unknown (misspelled) key explains the rest (the real key then shows up as missing): report it first. A
    # model says extra_forbidden, an options dataclass unexpected_keyword_argument.
    e = next((x for x in errors if x["type"] in _UNKNOWN_KEY), errors[0])
    loc = tuple(e["loc"])
    valid, where = _walk(Scenario, loc)
    if e["type"] in _UNKNOWN_KEY:
        close = difflib.get_close_matches(str(loc[-1]), valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{source}: unknown key {where!r}{hint}; valid keys there: {', '.join(valid)}"
    if e["type"] == "union_tag_invalid":  # locator.method names no registered locator
        tags = [s.strip("'") for s in str(e.get("ctx", {}).get("expected_tags", "")).split(", ") if s]
        tag = str(e.get("ctx", {}).get("tag", ""))
        close = difflib.get_close_matches(tag, tags, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{source}: {where}.method {tag!r} is unknown{hint}; valid: {', '.join(tags)}"
    if e["type"] == "missing" and loc and isinstance(loc[-1], int):  # a list shorter than its key needs
        return f"{source}: {where.rsplit('.', 1)[0]}: too few values (item {int(loc[-1]) + 1} is missing)"
    if e["type"] == "missing":
        return f"{source}: missing key {where!r}"
    if e["type"] == "value_error":  # a model's own check: its message says what is valid
        reason = str(e.get("ctx", {}).get("error", e["msg"]))
        return f"{source}: {reason}" if where == "<top level>" else f"{source}: {where}: {reason}"
    more = f" (+{len(errors) - 1} more problems)" if len(errors) > 1 else ""
    got = e.get("input")
    if isinstance(got, str) and e["type"] in _NUMBER_TYPES:  # ``seed: "12"``: typed, never read from text
        return f"{source}: {where}: a number is needed, got the text {got!r} (write it without quotes){more}"
    if isinstance(got, tuple):
        got = list(got)
    return f"{source}: {where}: {e['msg']} (got {got!r}){more}"


def _coerced(raw: Any, value: Any, path: tuple[str, ...]) -> tuple[str, Any, str] | None:
    """The first value pydantic's lax mode converted from another type (text or a bool to a number, a number to
    a bool, 12.0 to an integer): (its key, what the file gave, what was needed); None when every value was given as
    its type."""
    if isinstance(raw, dict) and isinstance(value, dict):
        for k, v in raw.items():
            if k in value:
                found = _coerced(v, value[k], (*path, str(k)))
                if found is not None:
                    return found
        return None
    if isinstance(raw, tuple) and isinstance(value, (tuple, list)) and len(raw) == len(value):
        for i, (r, v) in enumerate(zip(raw, value, strict=True)):
            found = _coerced(r, v, (*path, str(i)))
            if found is not None:
                return found
        return None
    where = ".".join(path)
    if isinstance(value, bool) and not isinstance(raw, bool):
        return where, raw, "true or false"
    if isinstance(value, (int, float)) and not isinstance(value, bool) and isinstance(raw, (str, bool)):
        return where, raw, "a number"
    if isinstance(value, int) and not isinstance(value, bool) and isinstance(raw, float):
        return where, raw, "a whole number (no decimal point)"
    return None


def resolve(name_or_path: str | Path) -> Path:
    """``fence1`` -> ``scenarios/fence1.yaml``; a path is taken as is."""
    p = Path(name_or_path)
    if p.suffix in (".yaml", ".yml") or p.exists():
        if not p.is_file():
            raise ScenarioError(f"scenario file {str(p)!r} does not exist")
        return p
    candidate = SCENARIO_DIR / f"{name_or_path}.yaml"
    if candidate.is_file():
        return candidate
    names = available()
    close = difflib.get_close_matches(str(name_or_path), names, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise ScenarioError(f"no scenario named {str(name_or_path)!r}{hint}; available: {', '.join(names)}")


def available() -> list[str]:
    """Names of the scenarios shipped in ``scenarios/`` (sub-folders as ``faults/name``)."""
    return sorted(str(p.relative_to(SCENARIO_DIR).with_suffix("")) for p in SCENARIO_DIR.rglob("*.yaml"))


def from_dict(data: Any, base_dir: Path, source: str = "<scenario>") -> Scenario:
    """Validate a parsed YAML mapping into a :class:`Scenario`; paths inside resolve against ``base_dir``."""
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: a scenario must be a YAML mapping of keys, got {type(data).__name__}")
    data = frozen(with_procedures_file(data, base_dir, source), source)
    try:
        scenario = Scenario.model_validate({**data, "base_dir": str(base_dir)})
    except ValidationError as err:
        raise ScenarioError(_explain(err, source)) from None
    coerced = _coerced(data, scenario.model_dump(), ())
    if coerced is not None:  # typed: ``seed: "12"`` or ``true`` for a number is refused, never read as 12 or 1
        where, got, wanted = coerced
        quotes = " (write it without quotes)" if isinstance(got, str) else ""
        raise ScenarioError(f"{source}: {where}: {wanted} is needed, got {got!r}{quotes}")
    if not scenario.map_path.is_file():
        looked = ", then ".join(str(p) for p in dict.fromkeys(scenario.map_candidates))
        raise ScenarioError(f"{source}: map.file {scenario.map.file!r} does not exist (looked at {looked})")
    return scenario


def from_yaml(text: str, base_dir: Path = SCENARIO_DIR, source: str = "<inline>") -> Scenario:
    """Parse and validate scenario YAML text (used by tests for tiny inline scenarios)."""
    return from_dict(parse(text, source), base_dir, source)


def load(name_or_path: str | Path) -> Scenario:
    """Load a scenario by name (``fence1``) or path."""
    path = resolve(name_or_path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ScenarioError(f"cannot read scenario {str(path)!r}: {err}") from None
    return from_yaml(text, path.parent, str(path.name))
