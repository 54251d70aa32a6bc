"""The job journal: records written whole and read back, a torn last line left out with a warning, a damaged or
foreign file refused with its code, what a resume still has to weld, the reports built from it, and the stop
signals turned into an orderly stop (the arc never cut mid-bead)."""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path
from typing import Any

import pytest

from cell.errors import EXIT_HANGUP, EXIT_INTERRUPTED, EXIT_TERMINATED, JournalError, JournalFault
from cell.export.reports.journal_report import joined_report, stopped_job_report
from cell.journal import Interrupted, JournalWriter, deferred, read_journal, stop_on_signals
from cell.journal.writer import _parse_hook

PROV = {"scenario_sha256": "aa", "map_sha256": "bb", "seed": 12}
SEAMS = ["S1", "S2", "S3", "S4"]


def _located(w: JournalWriter, side: str, found: list[str], hidden: list[str] = ()) -> None:  # type: ignore[assignment]
    seams = [{"id": s, "status": "found", "confidence": 0.9} for s in found]
    seams += [{"id": s, "status": "not_visible", "confidence": 0.0} for s in hidden]
    w.write("located", side=side, seams=seams)


def _weld(w: JournalWriter, seam: str, t: float, side: str = "A", *, off: bool = True) -> None:
    w.write("arc_on", side=side, seam=seam, t_s=t)
    if off:
        w.write("arc_off", side=side, seam=seam, complete=True, t_on_s=t, t_off_s=t + 5.0, tcp_rms_mm=0.05)


def _job(path: Path) -> JournalWriter:
    w = JournalWriter.create(path)
    w.write("start", **PROV, options={"sides": "all"})
    _located(w, "A", SEAMS[:3], SEAMS[3:])
    w.write("planned", side="A", order=SEAMS[:3])
    return w


def test_records_are_whole_lines_read_back_in_order_with_the_job_state(tmp_path: Path) -> None:
    path = tmp_path / "r.journal.jsonl"
    w = _job(path)
    _weld(w, "S1", 2.0)
    _weld(w, "S2", 9.0, off=False)  # killed with the arc on
    w.close()
    lines = path.read_bytes().split(b"\n")
    assert lines[-1] == b"" and all(json.loads(x)["run"] == "r1" for x in lines[:-1])
    assert [json.loads(x)["seq"] for x in lines[:-1]] == list(range(1, len(lines)))
    st = read_journal(path)
    assert st.runs == ("r1",) and st.start["seed"] == 12 and st.end is None and st.resumable
    assert set(st.welds) == {"S1"} and st.welds["S1"].t_off_s == 7.0 and st.welds["S1"].side == "A"
    assert set(st.interrupted) == {"S2"} and not st.interrupted["S2"].done  # an arc with no off: not welded
    assert st.turn is None and st.next_run() == "r2"


def test_a_torn_last_line_is_left_out_with_a_warning(tmp_path: Path) -> None:
    path = tmp_path / "j.jsonl"
    w = _job(path)
    _weld(w, "S1", 2.0)
    w.close()
    with path.open("ab") as f:
        f.write(b'{"kind":"arc_on","run":"r1","seq":9,"seam":"S2","t_')  # a write cut by SIGKILL
    st = read_journal(path)
    assert set(st.welds) == {"S1"} and not st.interrupted
    assert len(st.warnings) == 1 and "torn" in st.warnings[0]


@pytest.mark.parametrize(
    ("content", "code"),
    [
        (b"hello world\n", JournalFault.FOREIGN),
        (b'{"kind":"journal","format":"other","version":1}\n', JournalFault.FOREIGN),
        (b'{"kind":"journal","format":"cell-journal","version":99}\n', JournalFault.FOREIGN),
        (b'{"kind":"journal","format":"cell-journal","version":1}\n{"kind":"st\n{"kind":"end"}\n', JournalFault.TORN),
        (b'{"kind":"journal","format":"cell-journal","version":1}\n', JournalFault.FOREIGN),  # no job started
    ],
)
def test_a_damaged_or_foreign_file_is_refused_with_its_code(tmp_path: Path, content: bytes, code: JournalFault) -> None:
    path = tmp_path / "j.jsonl"
    path.write_bytes(content)
    with pytest.raises(JournalError) as e:
        read_journal(path)
    assert e.value.code is code and e.value.exit_code == 2 and "\n" not in e.value.message
    with pytest.raises(JournalError) as e:
        read_journal(tmp_path / "missing.jsonl")
    assert e.value.code is JournalFault.MISSING


def test_a_resume_appends_a_run_and_never_counts_a_seam_twice(tmp_path: Path) -> None:
    path = tmp_path / "j.jsonl"
    w = _job(path)
    _weld(w, "S1", 2.0)
    _weld(w, "S2", 9.0, off=False)
    w.write("end", outcome="interrupted", exit_code=143)
    w.close()
    st = read_journal(path)
    assert st.resumable and st.end is not None and st.end["exit_code"] == 143
    w2 = JournalWriter(path, st.next_run(), seq=len(st.records))
    w2.write("start", **PROV, resume_of=["r1"])
    _located(w2, "A", ["S2", "S3"], ["S4"])
    _weld(w2, "S2", 1.0)
    _weld(w2, "S3", 8.0)
    w2.write("turned", side="B", axis="x", rotation_deg=180.0, exposed=["S4"])
    st2 = read_journal(path)
    assert st2.runs == ("r1", "r2") and {k: w.run for k, w in st2.welds.items()} == {"S1": "r1", "S2": "r2", "S3": "r2"}
    assert not st2.interrupted and st2.turn is not None and st2.turn["exposed"] == ["S4"]
    assert st2.end is None  # r2 has not ended: r1's end is not the last run's
    w2.write("end", outcome="complete", exit_code=0)
    w2.close()
    assert not read_journal(path).resumable


def test_the_stopped_report_lists_each_weld_done_and_none_that_was_not(tmp_path: Path) -> None:
    path = tmp_path / "j.jsonl"
    w = _job(path)
    _weld(w, "S1", 2.0)
    _weld(w, "S2", 9.0, off=False)
    w.close()
    rep = stopped_job_report(read_journal(path), {"scenario": "x", "error": {"exit_code": 130}})
    by = {s["id"]: s for s in rep["seams"]}
    assert rep["welded"] == 1 and [s["id"] for s in rep["seams"]] == SEAMS
    assert by["S1"]["welded"] and by["S1"]["run"] == "r1" and by["S1"]["tcp_error_mm"]["rms"] == 0.05
    assert not by["S2"]["welded"] and by["S2"]["weld_reason_code"] == "interrupted"
    assert not by["S3"]["welded"] and by["S3"]["weld_reason_code"] == "not_executed" and by["S3"]["planned"]
    assert by["S4"]["weld_reason_code"] == "not_visible" and rep["flip"] is None
    assert [s["kind"] for s in rep["stages"]] == ["start", "located", "planned"]


def test_a_resumed_runs_report_names_the_run_of_every_weld(tmp_path: Path) -> None:
    path = tmp_path / "j.jsonl"
    w = _job(path)
    _weld(w, "S1", 2.0)
    w.close()
    w2 = JournalWriter(path, "r2", seq=100)
    _weld(w2, "S2", 1.0)
    w2.close()
    mine: dict[str, Any] = {
        "seams": [{"id": "S2", "welded": True, "side": "A"}, {"id": "S3", "welded": False, "side": "A"}],
        "summary": {"seams": 2, "visible": 2, "found": 2},
        "welded": 1,
    }
    rep = joined_report(mine, read_journal(path), "r2", on_b=False)
    assert [(s["id"], s.get("run"), s["welded"]) for s in rep["seams"]] == [
        ("S1", "r1", True),
        ("S2", "r2", True),
        ("S3", None, False),
        ("S4", None, False),
    ]
    assert rep["welded"] == 2 and rep["summary"]["seams"] == 3 and rep["journal"]["runs"] == ["r1"]


def test_stop_signals_raise_once_with_the_shells_exit_codes() -> None:
    for sig, code in (
        (signal.SIGINT, EXIT_INTERRUPTED),
        (signal.SIGTERM, EXIT_TERMINATED),
        (signal.SIGHUP, EXIT_HANGUP),
    ):
        before = signal.getsignal(sig)
        with pytest.raises(Interrupted) as e, stop_on_signals():
            os.kill(os.getpid(), sig)
            for _ in range(10**6):  # the handler runs at the next bytecode
                pass
        assert e.value.exit_code == code and e.value.name == sig.name and isinstance(e.value, KeyboardInterrupt)
        assert signal.getsignal(sig) is before  # the previous handler is back


def test_a_signal_during_a_weld_waits_for_its_arc_off() -> None:
    done = []
    with pytest.raises(Interrupted) as e, stop_on_signals():
        with deferred():
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(10**5):
                pass
            done.append("arc off")  # the weld went on to its end
        done.append("next seam")  # never reached
    assert done == ["arc off"] and e.value.signum == signal.SIGTERM


def test_the_test_hook_names_a_record_its_seam_and_its_count() -> None:
    assert _parse_hook("arc_on:POST_L>TOP_RAIL:+x@2=TERM") == ("arc_on", "POST_L>TOP_RAIL:+x", 2, signal.SIGTERM)
    assert _parse_hook("turned=SIGHUP") == ("turned", "", 1, signal.SIGHUP)
    assert _parse_hook("") is None and _parse_hook("turned=SIGNOPE") is None


def test_a_resume_is_refused_for_another_job_a_finished_one_and_a_new_job_never_replaces_an_unfinished_one(
    tmp_path: Path,
) -> None:
    from cell.cli.journal import open_job, resumed

    path = tmp_path / "r.journal.jsonl"
    w = _job(path)
    w.close()
    assert resumed(tmp_path, PROV).path == path  # the folder: its one journal
    with pytest.raises(JournalError) as e:
        resumed(path, {**PROV, "seed": 13})
    assert e.value.code is JournalFault.OTHER_JOB and "seed" in e.value.message
    with pytest.raises(JournalError) as e:
        open_job(path, None, PROV, {})
    assert e.value.code is JournalFault.UNFINISHED
    w = JournalWriter(path, "r1", seq=9)
    w.write("end", outcome="complete", exit_code=0)
    w.close()
    with pytest.raises(JournalError) as e:
        resumed(path, PROV)
    assert e.value.code is JournalFault.FINISHED and "complete" in e.value.message
    log = open_job(path, None, PROV, {"sides": "all"})  # a finished job's journal: a new job starts afresh
    assert log is not None and [r["kind"] for r in read_journal(path).records] == ["journal", "start"]
    log.writer.close()
