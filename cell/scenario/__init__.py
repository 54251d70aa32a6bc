"""Scenario files: YAML -> validated, typed, frozen :class:`Scenario`.

Everything about a cell lives in a scenario file under ``scenarios/``, never in code. An unknown or misspelled key,
a value out of range or a missing file is a :class:`~cell.errors.ScenarioError` with a one-line message naming the
key and what is valid. Lengths in the file are metres (keys end in ``_m``) or millimetres (``_mm``), angles degrees
(``_deg``); :class:`Scenario` converts nothing implicitly: accessors named ``*_rad`` / ``X_*`` do it in one place."""

# cell_specs: what the cell is (map, part as built, table, robot, cameras, sensor model); run_specs: how it works
# (process, perception, re-scan, motion, export, simulation, simulated faults); locator_specs: which locator and its
# options; model: the Scenario itself; loading: files and names. The options classes of the stages are
# cell.config's dataclasses, composed here as sub-models.

from cell.scenario.cell_specs import (
    CalibrationSpec,
    CameraSpec,
    Deviation,
    DistortionSpec,
    ExtrinsicErrorSpec,
    MapSpec,
    NoiseSpec,
    PoseSpec,
    RobotSpec,
    SensorErrorSpec,
    TableSpec,
    WorkspaceSpec,
)
from cell.scenario.loading import REPO_ROOT, SCENARIO_DIR, available, from_dict, from_yaml, load, resolve
from cell.scenario.locator_specs import (
    LOCATOR_SPECS,
    AnyLocatorSpec,
    LocatorSpec,
    OursLocatorSpec,
    PaperLocatorSpec,
    RansacLocatorSpec,
    spec_method,
)
from cell.scenario.model import Scenario
from cell.scenario.realism_specs import BowSpec, GapsSpec, SpecularDropoutSpec, TacksPresentSpec
from cell.scenario.run_specs import (
    CameraFaultSpec,
    ExportSpec,
    FaultsSpec,
    MotionSpec,
    OccluderSpec,
    PerceptionSpec,
    ProcessSpec,
    RescanSpec,
    SimulationSpec,
)

__all__ = [
    "LOCATOR_SPECS",
    "REPO_ROOT",
    "SCENARIO_DIR",
    "AnyLocatorSpec",
    "BowSpec",
    "CalibrationSpec",
    "CameraFaultSpec",
    "CameraSpec",
    "Deviation",
    "DistortionSpec",
    "ExportSpec",
    "ExtrinsicErrorSpec",
    "FaultsSpec",
    "GapsSpec",
    "LocatorSpec",
    "MapSpec",
    "MotionSpec",
    "NoiseSpec",
    "OccluderSpec",
    "OursLocatorSpec",
    "PaperLocatorSpec",
    "PerceptionSpec",
    "PoseSpec",
    "ProcessSpec",
    "RansacLocatorSpec",
    "RescanSpec",
    "RobotSpec",
    "Scenario",
    "SensorErrorSpec",
    "SimulationSpec",
    "SpecularDropoutSpec",
    "TableSpec",
    "TacksPresentSpec",
    "WorkspaceSpec",
    "available",
    "from_dict",
    "from_yaml",
    "load",
    "resolve",
    "spec_method",
]
