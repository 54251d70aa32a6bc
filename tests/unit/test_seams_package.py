"""The seams package's public names: listed in ``cell.seams.__all__``, each loaded on first use from its module (that
nothing outside the package imports its private modules is an import-linter contract, pyproject.toml)."""

from __future__ import annotations

import importlib
import subprocess
import sys

import cell.seams


def test_every_public_name_resolves_to_its_module() -> None:
    for name in cell.seams.__all__:
        value = getattr(cell.seams, name)
        module = importlib.import_module(f"cell.seams.{cell.seams._HOME[name]}")
        assert getattr(module, name) is value, name
    assert set(cell.seams.__all__) <= set(dir(cell.seams))


def test_importing_the_scene_type_loads_no_locator() -> None:
    """The vocabulary a stage needs (``SeamScene``) comes without the locators' modules (scipy, the scenario)."""
    code = "import sys, cell.seams.base; print(sorted(m for m in sys.modules if m.startswith('cell.seams')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "['cell.seams', 'cell.seams.base']"
