"""pybullet without its banners: ``pybullet build time`` (stderr, on import) and ``argv[0]=`` (stdout, on every
connect) come from its C code, which writes to the file descriptors, not to ``sys.stdout``/``sys.stderr``.

Import ``pybullet`` and ``BulletClient`` from here (before anything else imports pybullet) and connect inside
:func:`silenced_fds`; stdout then carries only the command's results.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator


@contextlib.contextmanager
def silenced_fds() -> Iterator[None]:
    """Point file descriptors 1 and 2 at the null device for the duration: pybullet's C code prints its banners
    (``pybullet build time``, ``argv[0]=``) to the descriptors, not to sys.stdout, on import and on every connect."""
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        saved = (os.dup(1), os.dup(2))
    except OSError:  # no real descriptors (embedded, closed): nothing to protect
        yield
        return
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None).fflush(None)  # what the C code buffered goes to the null device too
        for fd, copy in zip((1, 2), saved, strict=True):
            os.dup2(copy, fd)
            os.close(copy)
        os.close(null)


with silenced_fds():
    import pybullet
    from pybullet_utils.bullet_client import BulletClient

__all__ = ["BulletClient", "pybullet", "silenced_fds"]
