"""The seams package's face names no module: importing the package, or the vocabulary a stage needs from it, loads
no locator (that nothing outside the package imports its private modules is an import-linter contract,
pyproject.toml)."""

from __future__ import annotations

import json
import subprocess
import sys


def _loaded(code: str) -> list[str]:
    code += "; print(json.dumps(sorted(m for m in sys.modules if m.startswith('cell.seams'))))"
    out = subprocess.run(
        [sys.executable, "-c", "import json, sys; " + code], capture_output=True, text=True, check=True
    )
    return list(json.loads(out.stdout))


def test_importing_the_package_loads_no_module() -> None:
    assert _loaded("import cell.seams") == ["cell.seams"]


def test_importing_the_scene_type_loads_no_locator() -> None:
    """The vocabulary a stage needs (``SeamScene``) comes without the locators' modules (scipy, the scenario)."""
    assert _loaded("import cell.seams.base") == ["cell.seams", "cell.seams.base"]


def test_the_registry_loads_a_locator_when_asked() -> None:
    assert "cell.seams.ours.locator" not in _loaded("import cell.seams.registry")
