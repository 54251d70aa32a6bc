"""Point the code's citations of the design notes at the repository's own docs.

Run from the repository root::

    .venv/bin/python tools/fix_citations.py            # rewrite in place, print what changed
    .venv/bin/python tools/fix_citations.py --check    # exit 1 when a citation is still to be rewritten
    .venv/bin/python tools/fix_citations.py PATH...    # other files or folders than the default ones

Rewrites, in ``cell/ tests/ benchmarks/ tools/ robots/`` (text files: .py, .yaml, .urdf, .toml, .md):

- ``REFERENCE section N``, ``REFERENCE.md section N`` and ``REFERENCE.md sections N and M`` -> ``docs/reference.md
  section N`` (the sections of docs/reference.md keep the numbers of the notes the code was written against);
- ``STYLE.md`` -> ``docs/architecture.md`` (frames and units, stages as values: both are described there).

A rewritten line that grows past the line length (120, as ruff's) is re-wrapped within its comment or docstring
paragraph: the words that do not fit move to the start of the next line when that line continues the same
paragraph (same indentation, same comment prefix); otherwise the line is listed for a hand fix.
"""

from __future__ import annotations

import argparse
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


def rewrap(lines: list[str], changed: set[int], limit: int = MAX_LINE) -> tuple[list[str], list[int]]:
    """Move the words of over-long ``changed`` lines onto the next line of their paragraph; return the lines and
    the (0-based) indexes still too long."""
    out = list(lines)
    todo = sorted(changed)
    left: list[int] = []
    while todo:
        i = todo.pop(0)
        if len(out[i]) <= limit:
            continue
        prefix = _prefix(out[i])
        nxt = i + 1
        code, comment = _split_comment(out[i])
        if code.strip() and comment:
            # A trailing comment after code: the comment goes on lines of its own above the code.
            indent = code[: len(code) - len(code.lstrip())]
            out[i : i + 1] = [*_wrap_words(comment, indent + "# ", limit), code.rstrip()]
            continue
        if nxt >= len(out) or not _continues(out[nxt], prefix):
            left.append(i)
            continue
        words = out[i].split(" ")
        moved: list[str] = []
        while len(words) > 1 and len(" ".join(words[:-1])) >= len(prefix):
            kept = " ".join(words)
            if len(kept) <= limit and kept.count("``") % 2 == 0:  # never split a ``literal``
                break
            moved.insert(0, words.pop())
        if not moved:
            left.append(i)
            continue
        out[i] = " ".join(words).rstrip()
        out[nxt] = prefix + " ".join(moved) + " " + out[nxt][len(prefix) :]
        todo.insert(0, nxt)
    return out, sorted(set(left))


def fix_file(path: Path) -> tuple[str, str, list[int]]:
    """(old text, new text, 1-based numbers of lines still over the limit) of one file."""
    old = path.read_text(encoding="utf-8")
    new = rewrite_text(old)
    if new == old:
        return old, new, []
    old_lines, new_lines = old.splitlines(), new.splitlines()
    changed = {i for i, (a, b) in enumerate(zip(old_lines, new_lines, strict=True)) if a != b}
    lines, left = rewrap(new_lines, changed)
    text = "\n".join(lines) + ("\n" if new.endswith("\n") else "")
    return old, text, [i + 1 for i in left]


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
