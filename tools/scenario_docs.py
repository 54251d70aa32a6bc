"""Generate ``docs/scenarios.md`` from the pydantic models of :mod:`cell.scenario`: every key of a scenario file.

Run from the repository root::

    .venv/bin/python tools/scenario_docs.py           # rewrite docs/scenarios.md
    .venv/bin/python tools/scenario_docs.py --check   # exit 1 when docs/scenarios.md differs from the models

The walk starts at ``Scenario.model_fields`` and descends into every sub-model (through ``X | None``, unions,
``dict[str, Model]`` and tuples). Per key: its dotted path (``<name>`` where the key is free, e.g. a camera's
name), its type, its unit (from a ``Field`` description or comment ``[unit]``, else from the name's suffix:
``_m``, ``_mm``, ``_deg``, ``_s``, ``_px``, ``_mm_s``), its default (``required`` when it has none), the
allowed range, and its description: the ``Field``'s description, the ``name : text`` entry of the class
docstring (for a field of fixed choices, else the docstring paragraph that explains them), and the comments on
and just above the field's line in the source of :mod:`cell.scenario`, in that order. Last, the scenarios shipped
in ``scenarios/`` (name, map, description): a new scenario file needs the page regenerated too.
"""

from __future__ import annotations

import argparse
import ast
import collections.abc
import dataclasses
import inspect
import io
import re
import sys
import tokenize
import types
import typing
from collections.abc import Iterator
from dataclasses import dataclass
from enum import Enum
from functools import cache
from pathlib import Path
from typing import Any, Literal, Union, get_args, get_origin

from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:  # run as a script from anywhere: the package is the repository's
    sys.path.insert(0, str(REPO))

from cell import scenario as scenario_module  # noqa: E402  (after the path set-up above)

OUT = REPO / "docs" / "scenarios.md"
COMMAND = ".venv/bin/python tools/scenario_docs.py"

# Longest suffix first: ``travel_speed_mm_s`` is mm/s, not s.
_SUFFIX_UNITS = (
    ("_mm_s", "mm/s"),
    ("_m_s", "m/s"),
    ("_deg_s", "deg/s"),
    ("_mm", "mm"),
    ("_m", "m"),
    ("_deg", "deg"),
    ("_rad", "rad"),
    ("_px", "px"),
    ("_s", "s"),
)
_BRACKET_UNIT = re.compile(r"\[([^\]\s]{1,12})\]")
_BOUNDS = (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<"))


@dataclass(frozen=True)
class Row:
    """One key of the scenario file."""

    key: str
    type: str
    unit: str
    default: str
    range: str
    description: str
    variant: bool = False  # the row that opens one member of a union (its keys follow)


def _is_model(tp: Any) -> bool:
    """A scenario model or an options dataclass of :mod:`cell.config` (a sub-model of the scenario)."""
    return isinstance(tp, type) and (issubclass(tp, BaseModel) or dataclasses.is_dataclass(tp))


@dataclass(frozen=True)
class _DataclassField:
    """A dataclass field seen as a pydantic ``FieldInfo`` (the attributes this generator reads)."""

    annotation: Any
    default: Any
    default_factory: Any
    metadata: list[Any]
    description: str | None = None
    exclude: bool = False
    discriminator: str | None = None


def _fields(model: type) -> dict[str, Any]:
    """Field name -> its FieldInfo (a model) or a :class:`_DataclassField` (an options dataclass; the bounds of an
    ``Annotated[T, Bounds(...)]`` become its metadata, as pydantic does for a model's field)."""
    if issubclass(model, BaseModel):
        return dict(model.model_fields)
    hints = typing.get_type_hints(model, include_extras=True)
    out: dict[str, Any] = {}
    for f in dataclasses.fields(model):
        tp, meta = _strip_annotated(hints[f.name])
        default = f.default if f.default is not dataclasses.MISSING else PydanticUndefined
        factory = f.default_factory if f.default_factory is not dataclasses.MISSING else None
        out[f.name] = _DataclassField(tp, default, factory, meta)
    return out


def _strip_annotated(tp: Any) -> tuple[Any, list[Any]]:
    """``Annotated[T, m...]`` -> (T, [m...]); anything else -> (tp, [])."""
    if get_origin(tp) is typing.Annotated:
        base, *meta = get_args(tp)
        return base, meta
    return tp, []


def _bounds(metadata: list[Any]) -> str:
    """``>= 0``, ``> 0, <= 1``... from pydantic/annotated-types constraints (or ``Field(...)`` inside Annotated)."""
    parts = []
    for m in metadata:
        inner = m.metadata if isinstance(m, FieldInfo) else [m]
        for c in inner:
            for attr, sign in _BOUNDS:
                value = getattr(c, attr, None)
                if value is not None:
                    parts.append(f"{sign} {value:g}" if isinstance(value, int | float) else f"{sign} {value}")
    return ", ".join(parts)


def _is_union(tp: Any) -> bool:
    return get_origin(tp) in (Union, types.UnionType)


def _type_name(tp: Any) -> str:
    """A reader's spelling of an annotation: ``float``, ``[float, float, float]``, ``"a" | "b"``, ``map of ...``."""
    tp, meta = _strip_annotated(tp)
    bound = _bounds(meta)
    if tp is type(None):
        name = "null"
    elif get_origin(tp) is Literal:
        name = " | ".join(f'"{a}"' if isinstance(a, str) else str(a) for a in get_args(tp))
    elif _is_union(tp):
        name = " | ".join(_type_name(a) for a in get_args(tp))
    elif get_origin(tp) is tuple:
        args = get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis:
            name = f"[{_type_name(args[0])}, ...]"
        else:
            name = "[" + ", ".join(_type_name(a) for a in args) + "]"
    elif get_origin(tp) in (dict, typing.Mapping, collections.abc.Mapping):
        _, value = get_args(tp)
        name = f"map of name -> {_type_name(value)}"
    elif get_origin(tp) in (list, typing.Sequence):
        name = f"list of {_type_name(get_args(tp)[0])}"
    elif isinstance(tp, type) and issubclass(tp, Enum):
        name = " | ".join(f'"{m.value}"' for m in tp)
    elif isinstance(tp, type):
        name = tp.__name__
    else:
        name = str(tp).replace("typing.", "")
    return f"{name} ({bound})" if bound else name


def _yaml_value(v: Any) -> str:
    """A default as it would be written in the YAML file."""
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, Enum):
        return _yaml_value(v.value)
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, float):
        return repr(float(v))
    if isinstance(v, tuple | list):
        return "[" + ", ".join(_yaml_value(x) for x in v) + "]"
    if isinstance(v, typing.Mapping):
        return "{" + ", ".join(f"{k}: {_yaml_value(x)}" for k, x in v.items()) + "}"
    return str(v)


def _default(field: FieldInfo) -> str:
    if field.default is not PydanticUndefined:
        value = field.default
    elif field.default_factory is not None:
        value = field.default_factory()  # type: ignore[call-arg]
    else:
        return "required"
    if isinstance(value, BaseModel) or (dataclasses.is_dataclass(value) and not isinstance(value, type)):
        models, _ = _models_in(field.annotation)
        return "the defaults below" if len(models) < 2 else f"the defaults of {type(value).__name__}"
    return _yaml_value(value)


def _unit(name: str, text: str) -> str:
    """The unit of a key: a ``[unit]`` in its description, else its name's suffix, else none."""
    found = _BRACKET_UNIT.search(text)
    if found and any(c.isalpha() for c in found.group(1)):
        return found.group(1)
    return next((unit for suffix, unit in _SUFFIX_UNITS if name.endswith(suffix)), "")


def _defining_class(model: type, name: str) -> type:
    """The class of ``model``'s MRO whose body declares field ``name`` (sub-models may inherit fields)."""
    for klass in model.__mro__:
        if name in vars(klass).get("__annotations__", {}):
            return klass
    return model


@cache
def _source_comments(klass: type) -> dict[str, str]:
    """Field name -> the comments on its lines and the comment block just above it, from the class source."""
    try:
        source = inspect.getsource(klass)
    except (OSError, TypeError):
        return {}
    lines = source.splitlines()
    comments: dict[int, str] = {}  # 1-based line -> comment text
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            comments[tok.start[0]] = tok.string.lstrip("#").strip()
    tree = ast.parse(inspect.cleandoc(source) if source.startswith((" ", "\t")) else source)
    out: dict[str, str] = {}
    body = tree.body[0].body if tree.body and isinstance(tree.body[0], ast.ClassDef) else []
    for node in body:
        if not (isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)):
            continue
        above: list[str] = []
        k = node.lineno - 1
        while k >= 1 and lines[k - 1].strip().startswith("#"):
            above.insert(0, comments.get(k, ""))
            k -= 1
        end = node.end_lineno or node.lineno
        own = [comments[i] for i in range(node.lineno, end + 1) if i in comments]
        out[node.target.id] = " ".join(t for t in (*above, *own) if t)
    return out


@cache
def _docstring_entries(klass: type) -> dict[str, str]:
    """``name : text`` entries of a class docstring (numpy style; ``a, b : text`` names several keys).

    An entry starts at a line start or after a sentence (``". "``) and runs to the next entry, a blank line or a
    line that starts a new sentence (a capital letter); indented continuation lines belong to it.
    """
    doc = inspect.cleandoc(klass.__doc__ or "")
    starts = list(re.finditer(r"(?:^|(?<=\. ))(\w+(?:, \w+)*) : ", doc, flags=re.MULTILINE))
    entries: dict[str, str] = {}
    for k, m in enumerate(starts):
        stop = starts[k + 1].start() if k + 1 < len(starts) else len(doc)
        text = doc[m.end() : stop]
        end = re.search(r"\n\s*\n|\n(?=[A-Z])", text)
        text = " ".join((text[: end.start()] if end else text).split())
        for name in m.group(1).split(","):
            entries[name.strip()] = text
    return entries


def _class_summary(klass: type) -> str:
    """The first paragraph of a class docstring, on one line."""
    doc = inspect.cleandoc(klass.__doc__ or "")
    return " ".join(doc.split("\n\n")[0].split())


def _rst_to_md(text: str) -> str:
    """Docstring markup to Markdown: ``x`` -> `x`, :class:`~a.b.C` -> `C`."""
    text = re.sub(r":\w+:`~?([\w.]+)`", lambda m: f"`{m.group(1).split('.')[-1]}`", text)
    return text.replace("``", "`")


def _choices_paragraph(klass: type, annotation: Any) -> str:
    """For a field of fixed choices: the class docstring's paragraph that explains two or more of them."""
    tp, _ = _strip_annotated(annotation)
    if get_origin(tp) is not Literal:
        return ""
    values = [str(v) for v in get_args(tp)]
    for paragraph in inspect.cleandoc(klass.__doc__ or "").split("\n\n"):
        if sum(f"``{v}``" in paragraph for v in values) >= 2:
            return " ".join(paragraph.split())
    return ""


def _description(model: type, name: str, field: Any) -> str:
    klass = _defining_class(model, name)
    entry = _docstring_entries(klass).get(name, "") or _choices_paragraph(klass, field.annotation)
    parts = [field.description or "", entry, _source_comments(klass).get(name, "")]
    seen: list[str] = []
    for p in parts:
        if p and p not in seen:
            seen.append(p)
    return _rst_to_md(" ".join(seen))


def _models_in(tp: Any) -> tuple[list[type], str]:
    """The sub-models an annotation leads to and the path step they sit under (``""`` or ``.<name>``)."""
    tp, _ = _strip_annotated(tp)
    if _is_model(tp):
        return [tp], ""
    if _is_union(tp):
        found = [m for a in get_args(tp) for m in _models_in(a)[0]]
        return found, ""
    if get_origin(tp) in (dict, typing.Mapping, collections.abc.Mapping):
        models, step = _models_in(get_args(tp)[1])
        return models, ".<name>" + step
    if get_origin(tp) in (tuple, list, typing.Sequence):
        found = [m for a in get_args(tp) if a is not Ellipsis for m in _models_in(a)[0]]
        return found, "[i]" if found else ""
    return [], ""


def _variant(model: type[BaseModel], field: FieldInfo) -> str:
    """For a member of a discriminated union: ``kind: "x"`` (the discriminator's value), else the class name."""
    disc = field.discriminator if isinstance(field.discriminator, str) else None
    if disc and disc in model.model_fields:
        values = get_args(_strip_annotated(model.model_fields[disc].annotation)[0])
        if values:
            return f"{disc}: {_yaml_value(values[0])}"
    return model.__name__


def rows(model: type, prefix: str = "") -> Iterator[Row]:
    """Every key under ``model`` (depth first, in declaration order), ``prefix`` its dotted path so far."""
    for name, field in _fields(model).items():
        if field.exclude:  # set by the loader, never written in a file
            continue
        key = f"{prefix}{name}"
        description = _description(model, name, field)
        models, step = _models_in(field.annotation)
        if models and not description:
            description = _rst_to_md(_class_summary(models[0])) if len(models) == 1 else ""
        yield Row(
            key=key,
            type=_type_name(field.annotation),
            unit="" if models else _unit(name, description),
            default=_default(field),
            range=_bounds(list(field.metadata)),
            description=description,
        )
        for sub in models:
            if len(models) > 1:
                summary = _rst_to_md(_class_summary(sub))
                variant = f"when `{_variant(sub, field)}`: {summary}"
                yield Row(f"{key}{step}", sub.__name__, "", "", "", variant, variant=True)
            yield from rows(sub, f"{key}{step}.")


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ").strip()


def _table(items: list[Row]) -> list[str]:
    out = ["| key | type | unit | default | range | description |", "|---|---|---|---|---|---|"]
    for r in items:
        plain = r.default in ("", "required") or r.default.startswith("the defaults")
        default = r.default if plain else f"`{r.default}`"
        cells = (f"`{r.key}`", _cell(r.type), r.unit, _cell(default), _cell(r.range), _cell(r.description))
        out.append("| " + " | ".join(cells) + " |")
    return out


def render() -> str:
    """The whole of ``docs/scenarios.md``."""
    top = scenario_module.Scenario
    paragraphs = inspect.cleandoc(scenario_module.__doc__ or "").split("\n\n")
    intro = paragraphs[1] if len(paragraphs) > 1 else ""  # the first is the summary line
    lines = [
        "# Scenario files: every key",
        "",
        f"<!-- Generated from the models of cell.scenario by `{COMMAND}`; do not edit by hand. -->",
        "",
        " ".join(_rst_to_md(intro).split()),
        "",
        "A scenario is named by its file under `scenarios/` (`fence1`, `faults/camera-dead`) or given as a path; "
        "file paths inside it are relative to the file. `<name>` in a key is a name you choose (a camera, a part); "
        "`required` keys have no default. Ranges are checked when the file is loaded.",
        "",
        f"## Top level (`{top.__name__}`)",
        "",
        " ".join(_rst_to_md(_class_summary(top)).split()),
        "",
    ]
    all_rows = list(rows(top))
    scalars = [r for r in all_rows if "." not in r.key and not r.variant]
    lines += _table(scalars)
    for head in scalars:
        sub = [
            r
            for r in all_rows
            if r.key.startswith((head.key + ".", head.key + "[")) or (r.variant and r.key.startswith(head.key))
        ]
        if not sub:
            continue
        lines += ["", f"## `{head.key}`", "", _cell(head.description), ""]
        lines += _table(sub)
    return "\n".join(lines + _shipped()) + "\n"


def _shipped() -> list[str]:
    """The scenarios shipped in ``scenarios/``: name, map and description, one row each."""
    from cell.scenario import available, load

    out = ["", "## The scenarios in `scenarios/`", "", "| scenario | map | description |", "|---|---|---|"]
    for name in available():
        sc = load(name)
        out.append(f"| `{name}` | `{Path(sc.map.file).name}` | {_cell(sc.description)} |")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 when docs/scenarios.md is not what the models give")
    ap.add_argument("--out", type=Path, default=OUT, help="where to write (default docs/scenarios.md)")
    args = ap.parse_args(argv)
    text = render()
    if args.check:
        current = args.out.read_text(encoding="utf-8") if args.out.is_file() else ""
        if current != text:
            print(f"{args.out} is out of date with cell.scenario; regenerate it with {COMMAND}", file=sys.stderr)
            return 1
        return 0
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text, encoding="utf-8")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
