"""What an output path is, before anything is written to it: only a regular file (or a new one in an existing folder)
is ever written, a symbolic link is followed to its target (the link stays a link), and no missing folder is
created but the output folder itself (docs/cli.md, "Outputs"). Nothing here opens the path: opening a FIFO blocks,
opening a device may act."""

from __future__ import annotations

import errno
import os
import stat
import tempfile
from pathlib import Path

from cell.errors import OutputError, OutputFault

LOCK_NAME = ".cell.lock"  # the folder's lock (cell.outputs.lock); never an output's name

VALID_FILE = "valid: a regular file, or a new file in an existing folder"
VALID_FOLDER = "valid: an existing folder, or a new one in an existing folder"

_KINDS: tuple[tuple[int, OutputFault, str], ...] = (
    (stat.S_IFCHR, OutputFault.DEVICE, "a character device"),
    (stat.S_IFBLK, OutputFault.DEVICE, "a block device"),
    (stat.S_IFIFO, OutputFault.FIFO, "a FIFO (named pipe)"),
    (stat.S_IFSOCK, OutputFault.SOCKET, "a socket"),
    (stat.S_IFDIR, OutputFault.FOLDER, "a folder"),
)


def _shown(path: Path, target: Path) -> str:
    """How an error names the path: as asked, and the target when a link led elsewhere."""
    return repr(str(path)) if target == Path(os.path.abspath(path)) else f"{str(path)!r} (a link to {str(target)!r})"


def resolve(path: str | Path) -> Path:
    """The absolute path a write to ``path`` lands on: every symbolic link followed (a dangling link: where its
    target would be; a loop of links: the link where it loops)."""
    return Path(os.path.realpath(Path(path), strict=False))


def _looping(path: Path) -> bool:
    """realpath(strict=False) hands a looping link back unresolved: it is still a link, with no target."""
    try:
        os.stat(path)
    except OSError as e:
        return e.errno == errno.ELOOP
    return False


def _writable_folder(folder: Path, option: str, path: Path) -> None:
    """A file can be created in ``folder`` (a probe file: permission bits alone do not say, a read-only file
    system or an ACL does)."""
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as e:
        raise OutputError(
            f"{option} {str(path)!r}: cannot write in {str(folder)!r} ({e.strerror or e})",
            path=str(path),
            code=OutputFault.NOT_WRITABLE,
        ) from None


def check_file(path: str | Path, option: str = "output", *, probe: bool = True) -> Path:
    """The target a file output at ``path`` is written to (links followed), checked: it is a regular file the
    user may write, or does not exist and its folder does. OutputError (one line, its ``code``) otherwise;
    ``probe`` also creates and removes a file in the folder to prove it writable."""
    p = Path(path)
    target = resolve(p)
    if _looping(target):
        raise OutputError(f"{option} {str(p)!r} is a loop of symbolic links; {VALID_FILE}", path=str(p),
                          code=OutputFault.LINK_LOOP)  # fmt: skip
    shown = _shown(p, target)
    if target.name == LOCK_NAME:
        raise OutputError(f"{option} {shown} is the name of the folder's job lock; {VALID_FILE}", path=str(p),
                          code=OutputFault.RESERVED)  # fmt: skip
    try:
        mode = os.lstat(target).st_mode
    except (FileNotFoundError, NotADirectoryError):  # none there, or its folder is a file: said below
        mode = None
    except OSError as e:
        raise OutputError(f"{option} {shown} cannot be read ({e.strerror or e}); {VALID_FILE}", path=str(p),
                          code=OutputFault.NOT_WRITABLE) from None  # fmt: skip
    if mode is not None and not stat.S_ISREG(mode):
        fault, kind = next(((f, k) for t, f, k in _KINDS if stat.S_IFMT(mode) == t), (OutputFault.DEVICE, "no file"))
        what = "a folder, not a file name" if fault is OutputFault.FOLDER else f"{kind}, not a regular file"
        raise OutputError(f"{option} {shown} is {what}; {VALID_FILE}", path=str(p), code=fault)
    folder = target.parent
    if not folder.is_dir():
        what = "does not exist" if not folder.exists() else "is not a folder"
        raise OutputError(f"{option} {shown}: the folder {str(folder)!r} {what} (none is created); {VALID_FILE}",
                          path=str(p), code=OutputFault.NO_FOLDER)  # fmt: skip
    if mode is not None and not os.access(target, os.W_OK):
        raise OutputError(f"{option} {shown} is read-only (Permission denied); {VALID_FILE}", path=str(p),
                          code=OutputFault.NOT_WRITABLE)  # fmt: skip
    if probe:
        _writable_folder(folder, option, p)
    return target


def check_folder(path: str | Path, option: str = "output", *, create: bool = False) -> Path:
    """The folder an output folder at ``path`` is (links followed), checked: an existing folder files can be
    created in, or a missing one whose parent exists (made when ``create``). OutputError (one line) otherwise."""
    p = Path(path)
    target = resolve(p)
    shown = _shown(p, target)
    if _looping(target):
        raise OutputError(f"{option} {str(p)!r} is a loop of symbolic links; {VALID_FOLDER}", path=str(p),
                          code=OutputFault.LINK_LOOP)  # fmt: skip
    if target.exists() and not target.is_dir():
        mode = os.stat(target).st_mode
        kind = next((k for t, _, k in _KINDS if stat.S_IFMT(mode) == t), "a file")
        raise OutputError(f"{option} {shown} is {kind}, not a folder; {VALID_FOLDER}", path=str(p),
                          code=OutputFault.NOT_A_FOLDER)  # fmt: skip
    if not target.exists():
        if not target.parent.is_dir():
            raise OutputError(
                f"{option} {shown}: the folder {str(target.parent)!r} does not exist (only the last folder is "
                f"created); {VALID_FOLDER}",
                path=str(p),
                code=OutputFault.NO_FOLDER,
            )
        if not create:
            _writable_folder(target.parent, option, p)
            return target
        try:
            target.mkdir(exist_ok=True)
        except OSError as e:
            raise OutputError(f"{option} {shown}: cannot create it ({e.strerror or e}); {VALID_FOLDER}",
                              path=str(p), code=OutputFault.NOT_WRITABLE) from None  # fmt: skip
    _writable_folder(target, option, p)
    return target


def make_folder(path: str | Path, what: str = "output") -> Path:
    """``path`` as a folder to write into: made when missing (its parent must exist); OutputError otherwise."""
    return check_folder(path, what, create=True)
