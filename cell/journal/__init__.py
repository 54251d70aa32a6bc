"""The job journal (docs/journal.md): an append-only record of a weld job written as it goes, one JSON line per
step, each flushed and fsynced, so that an interrupt of any kind leaves what was done; its reader; what a resumed
job still has to weld; and the stop signals a job turns into an orderly stop."""

from cell.journal.reader import JobState, read_journal
from cell.journal.signals import Interrupted, deferred, stop_on_signals
from cell.journal.writer import FORMAT, NO_LOG, VERSION, JournalWriter, SideLog

__all__ = [
    "FORMAT",
    "NO_LOG",
    "VERSION",
    "Interrupted",
    "JobState",
    "JournalWriter",
    "SideLog",
    "deferred",
    "read_journal",
    "stop_on_signals",
]
