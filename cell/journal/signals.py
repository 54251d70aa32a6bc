"""The stop signals of a job (SIGINT, SIGTERM, SIGHUP) turned into one exception, :class:`Interrupted`, raised where
the job can stop cleanly: at once between steps, at the end of the seam when the arc is on (:func:`deferred`: a
cell controller's stop at the end of the weld, never a bead cut in the middle)."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from types import FrameType

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Interrupted(KeyboardInterrupt):
    """A stop signal arrived: ``signum``; its exit code is the shell's, 128 + the signal's number."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


@dataclass
class _State:
    received: int | None = None  # the first stop signal's number
    raised: bool = False  # Interrupted was raised once: later signals wait for the job's own end
    holding: int = 0  # depth of deferred() sections
    old: dict[int, object] = field(default_factory=dict)


_state: _State | None = None


def _handler(signum: int, _frame: FrameType | None) -> None:
    st = _state
    if st is None:
        raise Interrupted(signum)
    if st.received is None:
        st.received = signum
    if st.holding or st.raised:
        return
    st.raised = True
    raise Interrupted(st.received)


@contextlib.contextmanager
def stop_on_signals() -> Iterator[None]:
    """While the block runs, SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` (once: a second signal while the
    job writes its report is noted, not raised); the previous handlers come back after it. Outside the main thread
    (where Python cannot set a handler) nothing changes."""
    global _state
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    outer, st = _state, _State()
    for sig in STOP_SIGNALS:
        st.old[int(sig)] = signal.signal(sig, _handler)
    _state = st
    try:
        yield
    finally:
        for num, old in st.old.items():
            signal.signal(num, old)  # type: ignore[arg-type]
        _state = outer


@contextlib.contextmanager
def deferred() -> Iterator[None]:
    """A step that must not be cut (a seam's weld, arc on to arc off): a stop signal arriving inside it is held
    until the step ends, then raised."""
    st = _state
    if st is None:
        yield
        return
    st.holding += 1
    try:
        yield
    finally:
        st.holding -= 1
    if st.holding == 0 and st.received is not None and not st.raised:
        st.raised = True
        raise Interrupted(st.received)


def received() -> int | None:
    """The stop signal received in the running :func:`stop_on_signals` block (None: none, or no block)."""
    return _state.received if _state is not None else None
