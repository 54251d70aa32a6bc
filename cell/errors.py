"""One exception tree for the whole cell; the CLI maps each class to a documented exit code. Every error carries a
one-line message that names what was wrong and what is valid; each class also inherits the matching builtin (as
ezdxf's ``DXFValueError(DXFError, ValueError)``). The exit codes, one table for the whole cell: docs/architecture.md
section 4 (held against this module by tests/unit/test_errors.py)."""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_USAGE = 2
EXIT_PARTIAL = 3
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report it
EXIT_HANGUP = 129  # 128 + SIGHUP: cell weld stopped by its terminal closing
EXIT_TERMINATED = 143  # 128 + SIGTERM: cell weld stopped by a supervisor


class CellError(Exception):
    """Base of every error the cell raises on purpose."""

    exit_code: int = EXIT_INTERNAL

    def __init__(self, message: str) -> None:
        # One line: the CLI prints it as is.
        super().__init__(" ".join(message.split()))

    @property
    def message(self) -> str:
        return str(self.args[0])


class UsageError(CellError, ValueError):
    """A command-line value that cannot work (a seam not in the map, unknown units, --gui without a display),
    found before any work is done."""

    exit_code = EXIT_USAGE


class OutputFault(enum.StrEnum):
    """Why an output path cannot be written (docs/cli.md, "Outputs")."""

    FOLDER = "folder"  # a file was asked for and the path is a folder
    NOT_A_FOLDER = "not_a_folder"  # a folder was asked for and the path is something else
    DEVICE = "device"  # a character or block device (/dev/null, /dev/full, a disk)
    FIFO = "fifo"  # a named pipe
    SOCKET = "socket"  # a Unix socket
    NO_FOLDER = "no_folder"  # the folder it would go in does not exist (none is created)
    LINK_LOOP = "link_loop"  # a symbolic link that never ends in a path
    NOT_WRITABLE = "not_writable"  # permissions, a read-only file system
    RESERVED = "reserved"  # the name of the folder's lock file
    STDOUT = "stdout"  # '-' where standard output is not an option
    HELD = "held"  # another job holds the folder (its lock names it)
    WRITE_FAILED = "write_failed"  # the write itself failed (a full disk, a folder removed meanwhile)


class OutputError(CellError, OSError):
    """An output path cannot be written (found before the run when it can be; ``path`` is the one asked for,
    ``code`` says why)."""

    exit_code = EXIT_USAGE

    def __init__(self, message: str, *, path: str = "", code: OutputFault = OutputFault.WRITE_FAILED) -> None:
        super().__init__(message)
        self.path = path
        self.code = code


class CloudFault(enum.StrEnum):
    """Why a brought point cloud file (``cell locate CLOUD``) cannot be used."""

    MISSING = "missing"  # no such file, or not a file
    NOT_A_CLOUD = "not_a_cloud"  # neither PLY nor PCD by its content
    MALFORMED = "malformed"  # a PLY/PCD header or body that does not hold what it says (truncated, no x y z)
    UNSUPPORTED = "unsupported"  # a valid variant this reader does not read
    EMPTY = "empty"  # no points at all
    NOT_FINITE = "not_finite"  # every point has a NaN or infinite coordinate
    UNITS = "units"  # a size no cell's cloud has in the stated units (millimetres read as metres)


class CloudFileError(UsageError):
    """A brought point cloud file cannot be used: ``code`` says why, ``path`` names the file. Exit 2: it is an
    input of the command line, read before any work."""

    def __init__(self, message: str, *, code: CloudFault, path: str = "") -> None:
        super().__init__(message)
        self.code = code
        self.path = path


class JournalFault(enum.StrEnum):
    """Why a job journal cannot be resumed (docs/journal.md)."""

    MISSING = "missing"  # no such file, or no journal in the folder given
    FOREIGN = "foreign"  # not a cell journal (another file, another format version)
    TORN = "torn"  # a record cut inside the file (not its last line): the file was damaged
    OTHER_JOB = "other_job"  # another scenario, seed or map than the one asked for
    FINISHED = "finished"  # the job ended (complete or partial): nothing to resume
    UNFINISHED = "unfinished"  # a new job would replace the journal of a job that can still be resumed


class JournalError(UsageError):
    """A job journal that cannot be used as asked (``code`` says why); found before any work."""

    def __init__(self, message: str, code: JournalFault) -> None:
        super().__init__(message)
        self.code = code


class ScenarioError(CellError, ValueError):
    """The scenario file is missing, malformed, or has an unknown or out-of-range key."""

    exit_code = 10


class PositionerFault(enum.StrEnum):
    """Why a part cannot go on the scenario's positioner (docs/positioner.md, "The load")."""

    PAYLOAD = "payload"  # the part's mass over the rated payload
    TILT_TORQUE = "tilt_torque"  # its weight's moment about the tilt axis over the tilt axis's rated torque
    ROTATE_TORQUE = "rotate_torque"  # its weight's moment about the rotate axis over the rotate axis's rating


class PositionerLoadError(ScenarioError):
    """The part is too heavy, or its centre of mass too far out, for the positioner: ``code`` says which, ``value``
    the part's figure and ``needed`` the rating (kg or N m)."""

    def __init__(self, message: str, *, code: PositionerFault, value: float, needed: float) -> None:
        super().__init__(message)
        self.code = code
        self.value = value
        self.needed = needed


class MapError(CellError, ValueError):
    """The DXF welding map cannot be read or holds no usable seams/parts."""

    exit_code = 11


class MapUnitsError(MapError):
    """The DXF declares no usable units and the scenario states none."""

    exit_code = 12


class SensorError(CellError, RuntimeError):
    """A camera returned no image, or an image with no usable points.

    lost : camera name -> why it was dropped (empty when the failure is not one camera's).
    """

    exit_code = 13

    def __init__(self, message: str, *, lost: Mapping[str, str] | None = None) -> None:
        super().__init__(message)
        self.lost = dict(lost or {})


class AlignmentFailure(enum.StrEnum):
    """Why the map could not be aligned to the cloud."""

    NO_PARTS = "no_parts"  # the map has nothing to align
    TOO_FEW_POINTS = "too_few_points"  # the cloud has almost nothing to align to
    LOW_FITNESS = "low_fitness"  # too little of the cloud lies on the aligned map's surfaces
    TILTED = "tilted"  # the fit would tilt a part lying on the table
    AMBIGUOUS = "ambiguous"  # a shifted or turned map fits (almost) as well: a near-symmetry
    OFF_CLOUD = "off_cloud"  # the aligned map does not lie on the cloud (parts half seen)


class AlignmentError(CellError, RuntimeError):
    """The welding map could not be aligned to the point cloud: ``code`` says how, ``value`` and ``needed`` give
    the figure that decided it (a fitness, a coverage, an angle [rad]; nan where none applies)."""

    exit_code = 14

    def __init__(
        self, message: str, *, code: AlignmentFailure, value: float = math.nan, needed: float = math.nan
    ) -> None:
        super().__init__(message)
        self.code = code
        self.value = value
        self.needed = needed


class CaptureError(CellError, ValueError):
    """A recorded capture folder (docs/capture.md) cannot be read: a file missing, an image that is not a 16-bit
    PNG or disagrees with its CameraInfo, an unknown format or version. ``path`` names the file at fault."""

    exit_code = 16

    def __init__(self, message: str, *, path: str = "") -> None:
        super().__init__(message)
        self.path = path


class MotionError(CellError, RuntimeError):
    """Base of motion failures (IK, timing, planning)."""

    exit_code = 15


class IKError(MotionError):
    """Inverse kinematics did not converge to a pose within tolerance and limits."""


class TimingError(MotionError):
    """The trajectory generator (Ruckig) returned an error result."""


class PlanError(MotionError):
    """A plan violates limits, collides, or cannot be built."""


class CalibrationFault(enum.StrEnum):
    """Why ``cell calibrate`` refuses a camera (docs/calibration.md)."""

    NOT_SEEN = "not_seen"  # the board is seen (enough corners) at too few poses
    UNREACHABLE = "unreachable"  # too few of the planned board poses are within the arm's reach
    COLLIDING = "colliding"  # too few of the reachable board poses keep the arm clear of the cell and the part
    DEGENERATE = "degenerate"  # the poses lack rotation diversity (a pure translation, one rotation axis)
    BOARD_SIZE = "board_size"  # the depth image's scale disagrees with the board's stated size
    NOT_CONVERGED = "not_converged"  # the joint refinement did not reach a consistent solution


class CalibrationError(CellError, RuntimeError):
    """A camera cannot be calibrated: ``code`` says why, ``camera`` names it, ``value`` and ``needed`` give the
    figure that decided (nan where none applies)."""

    exit_code = 17

    def __init__(
        self,
        message: str,
        *,
        code: CalibrationFault,
        camera: str = "",
        value: float = math.nan,
        needed: float = math.nan,
    ) -> None:
        super().__init__(message)
        self.code = code
        self.camera = camera
        self.value = value
        self.needed = needed
