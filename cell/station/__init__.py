"""The station: the boundary between the pipeline's stages and a running cell.

:class:`Station` is the protocol (its ports); :class:`SimStation` serves it from the simulator; :func:`open_station`
is the one builder the pipeline calls (cf. Drake's ``MakeHardwareStation``).
"""

from __future__ import annotations

from cell.scenario import Scenario
from cell.station.arm import ROBOT_DIR, robot_urdf
from cell.station.ports import Arm, Station
from cell.station.sim import SimStation
from cell.types import WeldMap


def open_station(scenario: Scenario, weldmap: WeldMap, *, arm: Arm | None, gui: bool = False) -> SimStation:
    """The running cell of ``scenario`` built around the welding map ``weldmap`` (as drawn, frame M), with the arm
    ``arm`` (its model, home and scan configurations: :func:`cell.pipeline.geometry.robot_arm`; None: no robot)."""
    return SimStation(scenario, weldmap, arm=arm, gui=gui)


__all__ = ["ROBOT_DIR", "Arm", "SimStation", "Station", "open_station", "robot_urdf"]
