"""What made an output: the one record every report and robot program carries (docs/report.md, ``provenance``).

:func:`provenance` builds it once per command; the JSON reports store it under ``provenance`` and the KRL
program writes it as comment lines in its header (:func:`header_lines`), so a file found later says which code,
which inputs and which command produced it.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import importlib.metadata
import shlex
import subprocess
import sys
from collections.abc import Mapping, Sequence
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cell.scenario import Scenario

DISTRIBUTION = "weld-cell"  # the name in pyproject.toml
_REPO_ROOT = Path(__file__).resolve().parent.parent
UNKNOWN = "unknown"


@cache
def version() -> str:
    """The installed package's version (``unknown`` when it is run from a tree that was never installed)."""
    try:
        return importlib.metadata.version(DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError:
        return UNKNOWN


def _git(*args: str) -> str | None:
    try:
        done = subprocess.run(
            ["git", "-C", str(_REPO_ROOT), *args], capture_output=True, text=True, timeout=5, check=False
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


@cache
def git_commit() -> str:
    """The checkout's commit (40 hex digits), ``+dirty`` when tracked files differ from it; ``unknown`` outside a
    git checkout or without git."""
    sha = _git("rev-parse", "HEAD")
    if not sha:
        return UNKNOWN
    dirty = _git("status", "--porcelain", "--untracked-files=no")
    return sha + ("+dirty" if dirty else "")


def version_text() -> str:
    """``cell --version``: ``cell 0.1.0 (commit 0123456789ab)``, the commit when in a git checkout."""
    commit = git_commit()
    if commit == UNKNOWN:
        return f"cell {version()}"
    short = commit[:12] + ("+dirty" if commit.endswith("+dirty") else "")
    return f"cell {version()} (commit {short})"


def sha256_file(path: str | Path | None) -> str | None:
    """sha256 of a file's bytes (hex), None when there is no such file."""
    if path is None:
        return None
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def provenance(
    scenario: Scenario | None,
    *,
    scenario_file: str | Path | None = None,
    argv: Sequence[str] | None = None,
    now: dt.datetime | None = None,
    inputs: Mapping[str, str | Path] | None = None,
) -> dict[str, Any]:
    """The record of what made an output (JSON-ready): ``tool`` and ``version`` (package metadata), ``commit``
    (git, or ``unknown``), ``timestamp_utc`` (ISO 8601, seconds), ``command`` (the command line as typed, shell
    quoted), ``seed`` (the scenario's), ``scenario_file`` and ``scenario_sha256``, ``map_file`` and
    ``map_sha256`` (null where there is no such file). The resolved configuration is the report's ``config``.

    inputs : more input files by kind (``{"cloud": path, "map": path}`` for a brought cloud): each adds (or,
    for ``map``, sets) ``<kind>_file`` (resolved) and ``<kind>_sha256``."""
    stamp = (now or dt.datetime.now(dt.UTC)).astimezone(dt.UTC).replace(microsecond=0)
    words = list(sys.argv if argv is None else argv)
    if words:
        words[0] = Path(words[0]).name
    map_file = scenario.map_path if scenario is not None else None
    return {
        "tool": "cell",
        "version": version(),
        "commit": git_commit(),
        "timestamp_utc": stamp.isoformat().replace("+00:00", "Z"),
        "command": shlex.join(words),
        "seed": scenario.seed if scenario is not None else None,
        "scenario_file": str(Path(scenario_file).resolve()) if scenario_file is not None else None,
        "scenario_sha256": sha256_file(scenario_file),
        "map_file": str(map_file) if map_file is not None else None,
        "map_sha256": sha256_file(map_file),
    } | {
        key: value
        for kind, path in (inputs or {}).items()
        for key, value in ((f"{kind}_file", str(Path(path).resolve())), (f"{kind}_sha256", sha256_file(path)))
    }


def header_lines(record: Mapping[str, Any], prefix: str = ";- ") -> list[str]:
    """The record as comment lines (for a robot program's header), one ``key: value`` a line, ASCII only."""
    lines = [
        f"{prefix}Made by {record.get('tool', 'cell')} {record.get('version', UNKNOWN)}, commit"
        f" {record.get('commit', UNKNOWN)}, at {record.get('timestamp_utc', UNKNOWN)}"
    ]
    for key in ("command", "seed", "scenario_file", "scenario_sha256", "map_file", "map_sha256"):
        value = record.get(key)
        if value is not None:
            lines.append(f"{prefix}{key}: {value}")
    return [ln.encode("ascii", errors="replace").decode("ascii") for ln in lines]
