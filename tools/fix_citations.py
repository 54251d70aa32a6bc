"""Point the code's citations of the design notes at the repository's own docs.

Run from the repository root::

    .venv/bin/python tools/fix_citations.py            # rewrite in place, print what changed
    .venv/bin/python tools/fix_citations.py --check    # exit 1 when a citation is still to be rewritten
    .venv/bin/python tools/fix_citations.py PATH...    # other files or folders than the default ones

Rewrites, in ``cell/ tests/ benchmarks/ tools/ robots/`` (text files: .py, .yaml, .urdf, .toml, .md):

- ``REFERENCE section N``, ``REFERENCE.md section N`` and ``REFERENCE.md sections N and M`` -> ``docs/reference.md
  section N`` (the sections of docs/reference.md keep the numbers of the notes the code was written against);
- ``STYLE.md`` -> ``docs/architecture.md`` (frames and units, stages as values: both are described there).

A rewritten line of a Python file that grows past the line length (120, as ruff's) is re-wrapped within its
comment or docstring paragraph: the words that do not fit move to the start of the next line when that line
continues the same paragraph (same indentation, same comment prefix), else onto a new line of their own; a
trailing comment after code moves above the code. Code itself is never split: such a line is listed for a hand
fix. Other files (YAML, Markdown) have no line limit and are only rewritten.
"""

from __future__ import annotations

import argparse
import ast
import io
import re
import sys
import tokenize
from collections.abc import Iterator, Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_PATHS = ("cell", "tests", "benchmarks", "tools", "robots")
SUFFIXES = {".py", ".yaml", ".yml", ".urdf", ".toml", ".md"}
MAX_LINE = 120

# ``\b`` before REFERENCE keeps ``_REFERENCES`` (a pinocchio frame table) out; the look-ahead keeps words such as
# REFERENCES out. The section numbers may follow on the next line of a wrapped docstring.
_REFERENCE = re.compile(r"\bREFERENCE(?:\.md)?(?![\w.])(?=(\s+sections?\s+\d))")
_REFERENCE_FILE = re.compile(r"\bREFERENCE\.md\b")
_STYLE = re.compile(r"\bSTYLE\.md\b")
_SELF = Path(__file__).resolve()


def rewrite_text(text: str) -> str:
    """``text`` with every design-note citation pointed at docs/ (line lengths untouched)."""
    text = _REFERENCE.sub("docs/reference.md", text)
    text = _REFERENCE_FILE.sub("docs/reference.md", text)
    return _STYLE.sub("docs/architecture.md", text)


def _prefix(line: str) -> str:
    """The indentation and comment marker a line of a paragraph starts with (``"    # "``, ``"    "``)."""
    m = re.match(r"^(\s*(?:#+\s*)?)", line)
    return m.group(1) if m else ""


def _continues(line: str, prefix: str) -> bool:
    """Does ``line`` continue a paragraph whose lines start with ``prefix`` (no blank, no new item, no quotes)?"""
    if not line.startswith(prefix) or len(_prefix(line)) != len(prefix):
        return False
    rest = line[len(prefix) :]
    return bool(rest.strip()) and not rest.startswith(("-", "*", '"""', "'''", ":")) and not rest[0].isspace()


def _split_comment(line: str) -> tuple[str, str]:
    """(code, comment text) of a Python line with a trailing ``# comment`` outside strings; ("", "") otherwise."""
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(line + "\n").readline))
    except (tokenize.TokenError, SyntaxError, IndentationError):
        return "", ""
    for tok in tokens:
        if tok.type == tokenize.COMMENT:
            return line[: tok.start[1]], tok.string.lstrip("#").strip()
    return "", ""


def _wrap_words(text: str, prefix: str, limit: int) -> list[str]:
    """``text`` as lines of at most ``limit`` characters, each starting with ``prefix``."""
    lines, current = [], prefix
    for word in text.split():
        if current != prefix and len(current) + 1 + len(word) > limit:
            lines.append(current)
            current = prefix
        current += ("" if current == prefix else " ") + word
    return [*lines, current]


def _kinds(text: str, suffix: str) -> list[str]:
    """Per line: ``comment`` (a comment-only line), ``doc`` (inside a Python docstring) or ``code``."""
    lines = text.splitlines()
    kinds = ["comment" if line.lstrip().startswith("#") else "code" for line in lines]
    if suffix != ".py":
        return kinds
    try:
        tree = ast.parse(text)
    except SyntaxError:
        return kinds
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if not (isinstance(body, list) and body and isinstance(body[0], ast.Expr)):
            continue
        value = body[0].value
        if isinstance(value, ast.Constant) and isinstance(value.value, str):
            for k in range(value.lineno - 1, (value.end_lineno or value.lineno)):
                kinds[k] = "doc"
    return kinds


def _split_words(line: str, prefix: str, limit: int) -> tuple[str, list[str]]:
    """(what stays on the line, the words that move on) so that the line fits, never splitting a ``literal``."""
    words = line.split(" ")
    moved: list[str] = []
    while len(words) > 1 and len(" ".join(words[:-1])) >= len(prefix):
        kept = " ".join(words)
        if len(kept) <= limit and kept.count("``") % 2 == 0:
            break
        moved.insert(0, words.pop())
    while moved and len(words) > 1 and words[-1] in ("section", "sections"):  # "section N" stays together
        moved.insert(0, words.pop())
    return " ".join(words).rstrip(), moved


def rewrap(lines: list[str], changed: set[int], kinds: list[str], limit: int = MAX_LINE) -> list[str]:
    """Re-wrap the over-long ``changed`` lines within their comment or docstring paragraph.

    The words that do not fit move to the start of the next line when it continues the paragraph, else onto a
    new line of their own (comments and docstrings only); a trailing comment after code moves above the code.
    Code is never split. Lines are handled from the bottom up, so insertions never shift a line still to do.
    """
    out, kind = list(lines), list(kinds)
    for start in sorted(changed, reverse=True):
        todo = [start]
        while todo:
            i = todo.pop()
            if len(out[i]) <= limit:
                continue
            prefix = _prefix(out[i])
            code, comment = _split_comment(out[i]) if kind[i] == "code" else ("", "")
            if code.strip() and comment:
                indent = code[: len(code) - len(code.lstrip())]
                above = _wrap_words(comment, indent + "# ", limit)
                out[i : i + 1] = [*above, code.rstrip()]
                kind[i : i + 1] = ["comment"] * len(above) + ["code"]
                continue
            if kind[i] == "code":
                continue
            kept, moved = _split_words(out[i], prefix, limit)
            if not moved:
                continue
            out[i] = kept
            nxt = i + 1
            if nxt < len(out) and kind[nxt] == kind[i] and _continues(out[nxt], prefix):
                out[nxt] = prefix + " ".join(moved) + " " + out[nxt][len(prefix) :]
            else:
                out.insert(nxt, prefix + " ".join(moved))
                kind.insert(nxt, kind[i])
            todo.append(nxt)
    return out


def fix_file(path: Path) -> tuple[str, str, list[int]]:
    """(old text, new text, 1-based numbers of the lines the rewrite left over the limit) of one file."""
    old = path.read_text(encoding="utf-8")
    new = rewrite_text(old)
    if new == old or path.suffix != ".py":  # the line length is ruff's, for Python files only
        return old, new, []
    old_lines, new_lines = old.splitlines(), new.splitlines()
    changed = {i for i, (a, b) in enumerate(zip(old_lines, new_lines, strict=True)) if a != b}
    lines = rewrap(new_lines, changed, _kinds(new, path.suffix))
    was_long = {line for line in old_lines if len(line) > MAX_LINE}
    left = [k + 1 for k, line in enumerate(lines) if len(line) > MAX_LINE and line not in was_long]
    text = "\n".join(lines) + ("\n" if new.endswith("\n") else "")
    return old, text, left


def files(paths: Sequence[str]) -> Iterator[Path]:
    """Text files under ``paths`` (relative to the repository), this script excepted, in a stable order."""
    for p in paths:
        root = (REPO / p) if not Path(p).is_absolute() else Path(p)
        found = [root] if root.is_file() else sorted(root.rglob("*"))
        for f in found:
            if f.is_file() and f.suffix in SUFFIXES and "__pycache__" not in f.parts and f.resolve() != _SELF:
                yield f


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="*", default=list(DEFAULT_PATHS), help="files or folders (default: %(default)s)")
    ap.add_argument("--check", action="store_true", help="exit 1 when a citation is left to rewrite; write nothing")
    args = ap.parse_args(argv)
    stale, long_lines, count = [], [], 0
    for f in files(args.paths):
        old, new, left = fix_file(f)
        if new == old:
            continue
        count += 1
        rel = f.relative_to(REPO) if f.is_relative_to(REPO) else f
        stale.append(str(rel))
        long_lines += [f"{rel}:{n}" for n in left]
        if not args.check:
            f.write_text(new, encoding="utf-8")
            print(f"rewrote {rel}")
    if args.check:
        if stale:
            print(f"citations of the design notes left in: {', '.join(stale)}; run tools/fix_citations.py")
            return 1
        return 0
    print(f"{count} files rewritten")
    if long_lines:
        print(f"lines still over {MAX_LINE} characters (wrap by hand): {', '.join(long_lines)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
