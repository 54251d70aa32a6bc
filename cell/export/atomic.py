"""Writing an output file whole or not at all, with the permissions any other new file of the user gets."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from cell.errors import OutputError


def _umask() -> int:
    mask = os.umask(0o022)  # reading the umask means setting it: put it straight back
    os.umask(mask)
    return mask


def write_atomic(path: str | Path, data: bytes, *, what: str = "output") -> Path:
    """Write ``data`` to ``path`` atomically (a crash leaves the old file or the new one, never half of one),
    creating parent folders; the file gets ``0o666 & ~umask`` like any file the user creates (not the temporary
    file's 0600). OutputError (one line naming ``what`` and ``path``, never the temporary name) when it cannot."""
    p = Path(path)
    tmp: str | None = None
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".part", dir=p.parent)
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, p)
        tmp = None
    except OSError as e:
        raise OutputError(f"cannot write the {what} {str(p)!r}: {e.strerror or e}", path=str(p)) from None
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    return p
