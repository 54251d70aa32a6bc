"""Where the cell writes its files, and how: only regular files are written (a device, a FIFO, a socket or a folder
is refused; a symbolic link is written through to its target and stays a link; no missing folder is created but the
output folder itself), each file whole (a temporary file in its folder, fsync, rename), and one job at a time per
output folder (a lock that names the job holding it). Every output of the cell goes through here (docs/cli.md,
"Outputs")."""

from cell.outputs.lock import FolderLock, Holder, hold
from cell.outputs.paths import LOCK_NAME, check_file, check_folder, make_folder, resolve
from cell.outputs.whole import leftovers, replacing, write_atomic, write_text

__all__ = [
    "LOCK_NAME",
    "FolderLock",
    "Holder",
    "check_file",
    "check_folder",
    "hold",
    "leftovers",
    "make_folder",
    "replacing",
    "resolve",
    "write_atomic",
    "write_text",
]
