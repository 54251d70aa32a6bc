"""Opening a DXF file: every failure of ezdxf becomes one MapError naming the file; ezdxf's log goes to ours."""

from __future__ import annotations

import logging
import struct
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import ezdxf
from ezdxf.document import Drawing

from cell.errors import MapError

log = logging.getLogger("cell.weldmap")
_EZDXF = logging.getLogger("ezdxf")

# What ezdxf raises on malformed content besides its own errors (fuzzing found AssertionError for bad tags and
# struct.error in the binary ACIS reader). Caught at the boundary, never shown as a traceback.
MALFORMED = (
    ezdxf.DXFError,
    ValueError,
    KeyError,
    IndexError,
    TypeError,
    AttributeError,
    AssertionError,
    struct.error,
    ZeroDivisionError,
    OverflowError,
    RecursionError,
    UnicodeError,
)


def kind_of(exc: BaseException) -> str:
    """An exception's type as a message names it (``struct.error``, ``AssertionError``)."""
    t = type(exc)
    return t.__name__ if t.__module__ == "builtins" else f"{t.__module__.split('.')[0]}.{t.__name__}"


class _Forward(logging.Handler):
    """Hands ezdxf's records to ``cell.weldmap`` as DEBUG lines (the log file has them; stderr never)."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.count = 0

    def emit(self, record: logging.LogRecord) -> None:
        self.count += 1
        log.debug("ezdxf %s: %s", record.levelname.lower(), record.getMessage())


@contextmanager
def ezdxf_to_log() -> Iterator[_Forward]:
    """While reading, ezdxf logs into ours instead of Python's last-resort handler (raw lines on stderr)."""
    handler = _Forward()
    propagate = _EZDXF.propagate
    _EZDXF.addHandler(handler)
    _EZDXF.propagate = False
    try:
        yield handler
    finally:
        _EZDXF.removeHandler(handler)
        _EZDXF.propagate = propagate


def load(path: Path) -> Drawing:
    """The drawing in ``path``, strictly read (a cut file is refused, not half read)."""
    if not path.is_file():
        raise MapError(f"welding map {path} not found (or not a file); expected a DXF file")
    try:
        # Strict on purpose: ezdxf.recover "succeeds" on a truncated file, returning part of a drawing.
        return ezdxf.readfile(path)
    except ezdxf.DXFStructureError as exc:
        raise MapError(f"{path}: truncated or corrupt DXF ({exc}); expected a complete DXF file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MapError(f"{path}: not a readable DXF file ({exc}); expected an ASCII or binary DXF") from None
    except Exception as exc:  # ezdxf raises assorted errors on malformed input; never show a traceback
        raise MapError(f"{path}: not a valid DXF file ({kind_of(exc)}: {exc})") from None
