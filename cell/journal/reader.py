"""The journal read back: its records (a torn last line, a write cut by a kill, is left out with a warning), and
the job's state they describe: the runs, each seam's last word (located, welded, interrupted), the turn, how the
last run ended, and whether it can be resumed."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cell.errors import JournalError, JournalFault
from cell.journal.writer import FORMAT, VERSION

RESUMABLE = ("interrupted", "failed")  # the end outcomes a resume continues (and a run with no end: killed)


@dataclass(frozen=True)
class Weld:
    """One seam's weld as the journal holds it: which run and side, the arc on and off [s of the side's robot
    time], and the TCP error measured against the true seam [mm] where known."""

    seam: str
    run: str
    side: str
    t_on_s: float | None
    t_off_s: float | None = None
    tcp_rms_mm: float | None = None
    tcp_max_mm: float | None = None
    length_mm: float | None = None

    @property
    def done(self) -> bool:
        """The arc went off at the end of the weld (an arc on without its off: stopped mid-bead, not welded)."""
        return self.t_off_s is not None


@dataclass(frozen=True)
class JobState:
    """What a journal says of its job.

    records : every whole record, in order. start : the first run's ``start`` record (the job's scenario, seed,
    options). runs : the run ids in order. welds : per seam its completed weld (the first run that welded it).
    interrupted : seams whose arc went on with no off recorded (a kill mid-bead), not welded since. turn : the
    ``turn`` record of the turn made (None: the part was not turned). end : the last run's ``end`` record (None:
    killed). warnings : what was left out on reading (a torn last line)."""

    path: Path
    records: tuple[Mapping[str, Any], ...]
    start: Mapping[str, Any]
    runs: tuple[str, ...]
    welds: Mapping[str, Weld]
    interrupted: Mapping[str, Weld]
    turn: Mapping[str, Any] | None
    end: Mapping[str, Any] | None
    warnings: tuple[str, ...] = field(default=())

    @property
    def resumable(self) -> bool:
        """The last run stopped before its end (killed, interrupted, or failed on the way)."""
        return self.end is None or self.end.get("outcome") in RESUMABLE

    def next_run(self) -> str:
        """The id of the run a resume starts (``r<k+1>``)."""
        return f"r{len(self.runs) + 1}"

    def last(self, kind: str, **match: Any) -> Mapping[str, Any] | None:
        """The last record of ``kind`` whose fields equal ``match`` (None: there is none)."""
        for rec in reversed(self.records):
            if rec.get("kind") == kind and all(rec.get(k) == v for k, v in match.items()):
                return rec
        return None


def read_journal(path: Path) -> JobState:
    """The journal at ``path`` and its job's state. JournalError (exit 2): no such file, not a journal (a foreign
    file, a later format), a record torn inside the file (not at its end)."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as e:
        raise JournalError(f"cannot read journal {str(p)!r}: {e.strerror or e}", JournalFault.MISSING) from None
    lines = raw.split(b"\n")
    warnings: list[str] = []
    if lines and lines[-1] == b"":
        lines.pop()
    elif lines:  # no newline after the last line: a write cut short (a kill); its record was never whole
        lines.pop()
        warnings.append(f"journal {str(p)!r}: its last line is torn (a write cut short); ignored")
    records: list[dict[str, Any]] = []
    for n, line in enumerate(lines, 1):
        try:
            rec = json.loads(line)
        except (ValueError, UnicodeDecodeError):
            rec = None
        if not isinstance(rec, dict) or "kind" not in rec:
            fault = JournalFault.FOREIGN if n == 1 else JournalFault.TORN
            what = "not a cell journal" if n == 1 else f"line {n} is not a whole record"
            raise JournalError(f"journal {str(p)!r}: {what}; valid: a file cell weld wrote", fault)
        records.append(rec)
    if not records or records[0].get("kind") != "journal" or records[0].get("format") != FORMAT:
        raise JournalError(f"journal {str(p)!r}: not a cell journal (no {FORMAT} header)", JournalFault.FOREIGN)
    if records[0].get("version") != VERSION:
        v = records[0].get("version")
        raise JournalError(f"journal {str(p)!r}: format version {v}; valid: {VERSION}", JournalFault.FOREIGN)
    return _state(p, records, tuple(warnings))


def _state(path: Path, records: list[dict[str, Any]], warnings: tuple[str, ...]) -> JobState:
    starts = [r for r in records if r["kind"] == "start"]
    if not starts:
        raise JournalError(f"journal {str(path)!r}: no job started in it", JournalFault.FOREIGN)
    runs = tuple(dict.fromkeys(str(r["run"]) for r in starts))
    welds: dict[str, Weld] = {}
    open_: dict[tuple[str, str], Weld] = {}
    turn = None
    for r in records:
        kind = r["kind"]
        if kind == "arc_on":
            open_[(r["run"], r["seam"])] = Weld(r["seam"], r["run"], r.get("side", "A"), r.get("t_s"))
        elif kind == "arc_off":
            open_.pop((r["run"], r["seam"]), None)
            if r.get("complete", True):
                w = Weld(
                    r["seam"],
                    r["run"],
                    r.get("side", "A"),
                    r.get("t_on_s"),
                    r.get("t_off_s"),
                    r.get("tcp_rms_mm"),
                    r.get("tcp_max_mm"),
                    r.get("length_mm"),
                )
                welds.setdefault(r["seam"], w)
        elif kind == "turned":
            turn = r
    interrupted = {w.seam: w for w in open_.values() if w.seam not in welds}
    last_run = runs[-1]
    end = next((r for r in reversed(records) if r["kind"] == "end" and r["run"] == last_run), None)
    return JobState(path, tuple(records), starts[0], runs, welds, interrupted, turn, end, warnings)
