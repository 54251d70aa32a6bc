"""The whole scenario: one validated, frozen value for everything about a cell and a run."""

from __future__ import annotations

import zlib
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from cell.geometry import FloatArray
from cell.scenario.base import Model
from cell.scenario.calibration_specs import CalibrationRunSpec
from cell.scenario.cell_specs import CameraSpec, Deviation, MapSpec, RobotSpec, TableSpec
from cell.scenario.locator_specs import LocatorSpec, OursLocatorSpec
from cell.scenario.procedure_specs import ProcedureSpec, default_procedure
from cell.scenario.run_specs import (
    ExportSpec,
    FaultsSpec,
    MotionSpec,
    PerceptionSpec,
    ProcessSpec,
    RescanSpec,
    SimulationSpec,
)
from cell.scenario.turnover_specs import TurnoverSpec
from cell.types.procedure import WeldProcedure

MAP_DIR = Path(__file__).resolve().parents[2] / "maps"  # the repository's welding maps


class Scenario(Model):
    """A whole cell: map, as-built part, table, robot, cameras, seed and algorithm options."""

    name: str
    description: str = ""
    seed: Annotated[int, Field(ge=0)]
    map: MapSpec
    table: TableSpec
    robot: RobotSpec = RobotSpec()
    process: ProcessSpec = ProcessSpec()
    # The WPS table: the first row that fits a seam (joint, position, leg) welds it; none: one row from process.
    procedures: tuple[ProcedureSpec, ...] = ()
    procedures_file: str | None = None  # a YAML list of rows beside the scenario, read into procedures
    cameras: dict[str, CameraSpec]
    perception: PerceptionSpec
    locator: LocatorSpec = OursLocatorSpec()  # which locator runs (``method``) and its options
    rescan: RescanSpec = RescanSpec()
    motion: MotionSpec = MotionSpec()
    export: ExportSpec = ExportSpec()
    simulation: SimulationSpec = SimulationSpec()
    flip: TurnoverSpec = TurnoverSpec()  # turning the part over for its second side (docs/flip.md)
    calibration: CalibrationRunSpec = CalibrationRunSpec()  # the board and poses of cell calibrate
    # Set by the loader: the folder the file lives in (paths inside are relative to it).
    base_dir: str = Field(default=".", exclude=True)

    @field_validator("cameras")
    @classmethod
    def _cameras(cls, v: dict[str, CameraSpec]) -> dict[str, CameraSpec]:
        if not v:
            raise ValueError("at least one camera is needed")
        return v

    @model_validator(mode="after")
    def _fault_cameras(self) -> Scenario:
        unknown = sorted(set(self.faults.cameras) - set(self.cameras))
        if unknown:
            raise ValueError(
                f"simulation.faults.cameras names unknown camera(s) {', '.join(unknown)}; "
                f"cameras: {', '.join(self.cameras)}"
            )
        return self

    @model_validator(mode="after")
    def _nothing_in_the_table(self) -> Scenario:
        """A camera or the robot's base inside the table's box is a typing error (no depth image, no arm)."""
        t = self.table
        where = f"inside the table (centre {list(t.center_m)}, size {list(t.size_m)} m)"
        for name, cam in self.cameras.items():
            if t.holds(cam.eye_m):
                raise ValueError(f"cameras.{name}.eye_m {list(cam.eye_m)} is {where}; a camera stands outside it")
        if self.robot.urdf is not None and t.holds(self.robot.X_WR.xyz_m):
            raise ValueError(
                f"robot.X_WR.xyz_m {list(self.robot.X_WR.xyz_m)} is {where}; the base stands beside or on it"
            )
        return self

    @field_validator("procedures")
    @classmethod
    def _procedure_names(cls, v: tuple[ProcedureSpec, ...]) -> tuple[ProcedureSpec, ...]:
        names = [p.name for p in v]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(f"each procedure name once; {', '.join(twice)} given more than once")
        return v

    def weld_procedures(self) -> tuple[WeldProcedure, ...]:
        """The WPS table as values (rows in order), or the one procedure made from ``process:``."""
        pr = self.process
        if not self.procedures:
            return (default_procedure(pr.travel_speed_mm_s, pr.work_angle_deg, pr.travel_angle_deg),)
        return tuple(p.to_procedure(pr.work_angle_deg, pr.travel_angle_deg) for p in self.procedures)

    @property
    def map_candidates(self) -> tuple[Path, ...]:
        """Where ``map.file`` is looked for, in order: relative to the scenario's folder, then by its name in the
        repository's ``maps/`` (so a scenario copied elsewhere still finds a shipped map)."""
        return ((Path(self.base_dir) / self.map.file).resolve(), MAP_DIR / Path(self.map.file).name)

    @property
    def map_path(self) -> Path:
        """The map file: the first of :attr:`map_candidates` that exists (the first if none does)."""
        return next((p for p in self.map_candidates if p.is_file()), self.map_candidates[0])

    @property
    def noise(self) -> Literal["none", "realistic"]:
        """``simulation.noise``: the depth sensors' error model on or off."""
        return self.simulation.noise

    @property
    def deviations(self) -> dict[str, Deviation]:
        """``simulation.deviations``: part name -> how it was built differently from the drawing."""
        return self.simulation.deviations

    @property
    def faults(self) -> FaultsSpec:
        """``simulation.faults``: the failures the simulation plays."""
        return self.simulation.faults

    @property
    def X_WR(self) -> FloatArray:
        return self.robot.X_WR.X

    @property
    def X_WM(self) -> FloatArray:
        return self.map.X_WM.X

    def rng(self, purpose: str) -> np.random.Generator:
        """An independent, reproducible random stream for one consumer (camera name, 'ransac', ...).

        Streams are keyed by the scenario seed and a stable hash of ``purpose``, so adding a consumer never
        changes the numbers another consumer draws. There is no global RNG anywhere in the cell.
        """
        return np.random.default_rng([self.seed, zlib.crc32(purpose.encode())])

    def with_simulation(self, **changes: object) -> Scenario:
        """The scenario with these ``simulation`` keys changed (``noise=``, ``faults=``, ``deviations=``,
        ``placement_error=``); an unknown key is a ValueError, not a silently ignored attribute."""
        unknown = sorted(set(changes) - set(SimulationSpec.model_fields))
        if unknown:
            raise ValueError(f"no simulation key {', '.join(unknown)}; valid: {', '.join(SimulationSpec.model_fields)}")
        return self.model_copy(update={"simulation": self.simulation.model_copy(update=changes)})

    def with_noise(self, noise: Literal["none", "realistic"]) -> Scenario:
        return self.with_simulation(noise=noise)
