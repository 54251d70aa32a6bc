"""Loading scenarios: a name or a path -> YAML -> a validated :class:`Scenario`, or one ScenarioError line that
names the key and what is valid there."""

from __future__ import annotations

import difflib
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from cell.errors import ScenarioError
from cell.scenario.model import Scenario

REPO_ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO_DIR = REPO_ROOT / "scenarios"


def _format_loc(loc: tuple[int | str, ...]) -> str:
    return ".".join(str(p) for p in loc) or "<top level>"


def _valid_keys(model: type[BaseModel], loc: tuple[int | str, ...]) -> list[str]:
    """Field names valid at ``loc`` (the location of an unknown key), by walking the model tree."""
    current: Any = model
    free_key = False  # the next part of loc is a free dict key (a camera or part name)
    for part in loc[:-1]:
        if free_key:
            free_key = False
            continue
        if not (isinstance(current, type) and issubclass(current, BaseModel)) or not isinstance(part, str):
            return []
        f = current.model_fields.get(part)
        if f is None:
            return []
        ann = f.annotation
        args = getattr(ann, "__args__", ())
        free_key = getattr(ann, "__origin__", None) is dict
        # dict[str, Model] -> Model after the free key; Model | None -> Model
        candidates = [a for a in (ann, *args) if isinstance(a, type) and issubclass(a, BaseModel)]
        current = candidates[0] if candidates else ann
    if isinstance(current, type) and issubclass(current, BaseModel):
        return [k for k in current.model_fields if k != "base_dir"]
    return []


def _explain(err: ValidationError, source: str) -> str:
    errors = err.errors()
    # An unknown (misspelled) key explains the rest (the real key then shows up as missing): report it first.
    e = next((x for x in errors if x["type"] == "extra_forbidden"), errors[0])
    loc = tuple(e["loc"])
    where = _format_loc(loc)
    if e["type"] == "extra_forbidden":
        valid = _valid_keys(Scenario, loc)
        close = difflib.get_close_matches(str(loc[-1]), valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{source}: unknown key {where!r}{hint}; valid keys there: {', '.join(valid)}"
    if e["type"] == "missing":
        return f"{source}: missing key {where!r}"
    more = f" (+{len(errors) - 1} more problems)" if len(errors) > 1 else ""
    return f"{source}: {where}: {e['msg']} (got {e.get('input')!r}){more}"


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
    known = ", ".join(available())
    raise ScenarioError(f"no scenario named {str(name_or_path)!r}; available: {known}")


def available() -> list[str]:
    """Names of the scenarios shipped in ``scenarios/`` (sub-folders as ``faults/name``)."""
    return sorted(str(p.relative_to(SCENARIO_DIR).with_suffix("")) for p in SCENARIO_DIR.rglob("*.yaml"))


def from_dict(data: Any, base_dir: Path, source: str = "<scenario>") -> Scenario:
    """Validate a parsed YAML mapping into a :class:`Scenario`; paths inside resolve against ``base_dir``."""
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: a scenario must be a YAML mapping of keys, got {type(data).__name__}")
    try:
        scenario = Scenario.model_validate({**data, "base_dir": str(base_dir)})
    except ValidationError as err:
        raise ScenarioError(_explain(err, source)) from None
    if not scenario.map_path.is_file():
        raise ScenarioError(f"{source}: map.file {scenario.map.file!r} does not exist (looked at {scenario.map_path})")
    return scenario


def from_yaml(text: str, base_dir: Path = SCENARIO_DIR, source: str = "<inline>") -> Scenario:
    """Parse and validate scenario YAML text (used by tests for tiny inline scenarios)."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise ScenarioError(f"{source}: not valid YAML{where}: {getattr(err, 'problem', err)}") from None
    return from_dict(data, base_dir, source)


def load(name_or_path: str | Path) -> Scenario:
    """Load a scenario by name (``fence1``) or path."""
    path = resolve(name_or_path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ScenarioError(f"cannot read scenario {str(path)!r}: {err}") from None
    return from_yaml(text, path.parent, str(path.name))
