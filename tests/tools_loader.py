"""The scripts of ``tools/`` and ``benchmarks/`` as modules, for the tests that check what they generate or count
(neither folder is a package)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

REPO = Path(__file__).resolve().parents[1]


def _load(folder: str, name: str, key: str) -> ModuleType:
    """``FOLDER/NAME.py`` imported as the module ``key`` (once per session), its folder on the path for its siblings."""
    if key in sys.modules:
        return sys.modules[key]
    where = REPO / folder
    if str(where) not in sys.path:
        sys.path.insert(0, str(where))
    spec = importlib.util.spec_from_file_location(key, where / f"{name}.py")
    if spec is None or spec.loader is None:
        raise ImportError(f"no {name!r} in {where}")
    module = importlib.util.module_from_spec(spec)
    sys.modules[key] = module
    spec.loader.exec_module(module)
    return module


def load_tool(name: str) -> ModuleType:
    """``tools/NAME.py`` imported as the module ``tools_NAME``."""
    return _load("tools", name, f"tools_{name}")


def load_bench(name: str) -> ModuleType:
    """``benchmarks/NAME.py`` imported as the module ``NAME``."""
    return _load("benchmarks", name, name)
