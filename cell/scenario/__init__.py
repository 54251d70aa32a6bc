"""Scenario files: YAML -> validated, typed, frozen :class:`Scenario`.

Everything about a cell lives in a scenario file under ``scenarios/``, never in code. An unknown or misspelled key,
a value out of range or a missing file is a :class:`~cell.errors.ScenarioError` with a one-line message naming the
key and what is valid. Lengths in the file are metres (keys end in ``_m``) or millimetres (``_mm``), angles degrees
(``_deg``); :class:`Scenario` converts nothing implicitly: accessors named ``*_rad`` / ``X_*`` do it in one place.
"""

# cell_specs: what the cell is (map, part as built, table, robot, cameras, sensor model); run_specs: how it works
# (process, perception, locator, re-scan, simulated faults); model: the Scenario itself; loading: files and names.

from cell.scenario.cell_specs import (
    CameraSpec,
    Deviation,
    ExtrinsicErrorSpec,
    MapSpec,
    NoiseSpec,
    PoseSpec,
    RobotSpec,
    TableSpec,
    WorkspaceSpec,
)
from cell.scenario.loading import REPO_ROOT, SCENARIO_DIR, available, from_dict, from_yaml, load, resolve
from cell.scenario.model import Scenario
from cell.scenario.run_specs import (
    CameraFaultSpec,
    FaultsSpec,
    LocatorSpec,
    OccluderSpec,
    PaperLocatorSpec,
    PerceptionSpec,
    ProcessSpec,
    RescanSpec,
)

__all__ = [
    "REPO_ROOT",
    "SCENARIO_DIR",
    "CameraFaultSpec",
    "CameraSpec",
    "Deviation",
    "ExtrinsicErrorSpec",
    "FaultsSpec",
    "LocatorSpec",
    "MapSpec",
    "NoiseSpec",
    "OccluderSpec",
    "PaperLocatorSpec",
    "PerceptionSpec",
    "PoseSpec",
    "ProcessSpec",
    "RescanSpec",
    "RobotSpec",
    "Scenario",
    "TableSpec",
    "WorkspaceSpec",
    "available",
    "from_dict",
    "from_yaml",
    "load",
    "resolve",
]
