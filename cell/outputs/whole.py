"""Every output file written whole or not at all: a temporary file in the target's own folder, written, flushed to
the disk (fsync), then renamed over the target, and the folder's entry flushed too. A crash, a kill or a full disk
leaves the old file or the new one, never a part of one (at worst a ``.NAME.XXXXXXXX.part`` file beside it). The
target is checked again just before the rename: only a regular file is ever replaced; a symbolic link is written
through to its target and stays a link (docs/cli.md, "Outputs")."""

from __future__ import annotations

import contextlib
import os
import re
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path

from cell.errors import OutputError
from cell.outputs.paths import check_file

PART = re.compile(r"^\..+\.[a-z0-9_]{8}\.part(\.[^.]*)?$")  # the temporary files this module makes


def _umask() -> int:
    mask = os.umask(0o022)  # reading the umask means setting it: put it straight back
    os.umask(mask)
    return mask


def _mode(target: Path) -> int:
    """The new file's permissions: the replaced file's, else ``0o666 & ~umask`` like any file the user creates
    (not the temporary file's 0600)."""
    try:
        return stat.S_IMODE(os.stat(target).st_mode)
    except FileNotFoundError:
        return 0o666 & ~_umask()


def _sync_folder(folder: Path) -> None:
    """Flush the folder's entries (the rename) to the disk; a file system that cannot is left as it is."""
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _failed(what: str, path: Path, e: OSError) -> OutputError:
    if isinstance(e, OutputError):
        return e
    return OutputError(
        f"cannot write the {what} {str(path)!r}: {e.strerror or e}; what was there is left as it was", path=str(path)
    )


@contextlib.contextmanager
def replacing(path: str | Path, *, what: str = "output") -> Iterator[Path]:
    """A temporary path to write ``path``'s new content to (by name: a library that writes files itself), in the
    target's folder and with its suffix; when the block ends it is flushed and renamed over the target. An
    exception in the block, or a write that fails, removes it and leaves the target as it was; an OSError becomes
    an OutputError naming ``what`` and ``path`` (never the temporary name)."""
    p = Path(path)
    target = check_file(p, what, probe=False)
    try:
        fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=f".part{target.suffix}", dir=target.parent)
    except OSError as e:
        raise _failed(what, p, e) from None
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.chmod(tmp, _mode(target))
        check_file(p, what, probe=False)  # still a regular file (or none): never replace what another put there
        os.replace(tmp, target)
    except OSError as e:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise _failed(what, p, e) from None
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
    _sync_folder(target.parent)


def write_atomic(path: str | Path, data: bytes, *, what: str = "output") -> Path:
    """Write ``data`` to ``path`` whole (see the module); returns ``path``. OutputError (one line naming ``what``
    and ``path``, its ``code``) when it cannot: the path is not a regular file or its folder does not exist (no
    folder is created), or the write failed."""
    p = Path(path)
    with replacing(p, what=what) as tmp, open(tmp, "wb") as f:
        f.write(data)
    return p


def write_text(path: str | Path, text: str, *, what: str = "output") -> Path:
    """``text`` as UTF-8, written whole (:func:`write_atomic`)."""
    return write_atomic(path, text.encode("utf-8"), what=what)


def leftovers(folder: str | Path) -> list[Path]:
    """The temporary files a killed writer left in ``folder`` (never a file of another name)."""
    d = Path(folder)
    try:
        return sorted(p for p in d.iterdir() if PART.match(p.name) and p.is_file() and not p.is_symlink())
    except OSError:
        return []
