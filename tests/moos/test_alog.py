"""The alog codec (gateway.moos.alog): pLogger's bytes, our writer read back, bad input, and the real tools.

The real ``aloggrep`` and ``pLogger`` are used when they are on PATH (a MOOS-IvP build's ``bin``); pLogger runs
against our ``moos-db`` (loopback only) and, inside a private network namespace, against the real MOOSDB too.
"""

from __future__ import annotations

import importlib.util
import io
import math
import shutil
import subprocess
import time
from pathlib import Path

import pytest

from gateway.moos.alog import (
    PLOGGER_19_8,
    PLOGGER_24_8,
    AlogError,
    AlogReader,
    AlogWriter,
    format_banner,
    format_row,
    format_system_row,
    log_root_name,
    read_alog,
    records_to_dicts,
    to_dataframe,
)
from gateway.moos.testing import collect_mail, connected_comms, moosdb_process, real_moos_skip_reason
from util.process import ChildProcess, wait_until

# Written by the real pLogger (MOOS-IvP 24.8: 5 decimals, LOGSTART to 16 digits) on our moos-db.
REAL_PLOGGER = (
    b"%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%\n"
    b"%% LOG FILE:       ./LOG_ALPHA_28_11_2026_____10_07_44/LOG_ALPHA_28_11_2026_____10_07_44.alog\n"
    b"%% FILE OPENED ON  Thu Jan  1 00:00:00 1970\n"
    b"%% LOGSTART           1795860463.558901\n"
    b"%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%%\n"
    b"0.00129         DB_EVENT             MOOSDB_alpha    connected=pLogger \n"
    b"0.65224         DB_UPTIME            MOOSDB_alpha    2.05329      \n"
    b"0.65253         DB_VARSUMMARY        MOOSDB_alpha    DB_CLIENTS           10:07:44.211         MOOSDB_alpha"
    b"         0.0 Hz S  pLogger,            \n"
    b"DB_EVENT             10:07:43.560         MOOSDB_alpha         0.0 Hz S  connected=pLogger   \n"
    b" \n"
    b"2.08573         NAV_X                poker           3.50000      \n"
    b"2.08581         NAV_X                poker           -1234567.12346 \n"
    b"2.08582         STR_V                poker           hello world  with  spaces \n"
    b"2.08583         EMPTY_S              poker            \n"
    b"2.08585         BIN_V                poker           <MOOS_BINARY>File=LOG_ALPHA_28_11_2026_____10_07_44.blog,"
    b"Offset=53,Bytes=7</MOOS_BINARY>\n"
    b"2.08588         NL_V                 poker           line1\n"
    b"line2 \n"
    b"2.08591         NAN_V                poker           nan          \n"
)


def _tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        pytest.skip(f"the real {name} is not on PATH (a MOOS-IvP build's bin directory)")
    return path


# ---- pLogger's bytes ------------------------------------------------------------------------------------
def test_rows_are_byte_identical_to_real_plogger_rows() -> None:
    lines = REAL_PLOGGER.decode().splitlines(keepends=True)
    assert format_row(2.08573, "NAV_X", "poker", 3.5, fmt=PLOGGER_24_8) == lines[10]
    assert format_row(2.08581, "NAV_X", "poker", -1234567.123456789, fmt=PLOGGER_24_8) == lines[11]
    assert format_row(2.08582, "STR_V", "poker", "hello world  with  spaces", fmt=PLOGGER_24_8) == lines[12]
    assert format_row(2.08583, "EMPTY_S", "poker", "", fmt=PLOGGER_24_8) == lines[13]
    assert format_row(2.08591, "NAN_V", "poker", math.nan, fmt=PLOGGER_24_8) == lines[17]
    assert format_row(0.65224, "DB_UPTIME", "MOOSDB_alpha", 2.053291, fmt=PLOGGER_24_8) == lines[6]
    banner = format_banner("./LOG_ALPHA_28_11_2026_____10_07_44/LOG_ALPHA_28_11_2026_____10_07_44.alog",
                           1795860463.558901, opened_on=0.0, fmt=PLOGGER_24_8)
    epoch = time.ctime(0)  # pLogger always writes the epoch; we give opened_on=0 to compare
    assert banner == REAL_PLOGGER.decode()[: len(banner)].replace("Thu Jan  1 00:00:00 1970", epoch)


def test_the_19_8_release_format() -> None:
    """MOOS-IvP 19.8.1: row times with 3 decimals, LOGSTART with 12 significant digits (%20.12g)."""
    assert format_row(2.08573, "NAV_X", "poker", 3.5) == f"{'2.086':<15} {'NAV_X':<20} {'poker':<15} 3.50000      \n"
    assert "%% LOGSTART               1795860463.56\n" in format_banner("a.alog", 1795860463.558901, fmt=PLOGGER_19_8)
    assert format_row(-0.5, "V", "s", -math.nan).endswith(" -nan         \n")  # glibc prints the sign of a NaN
    assert format_row(1.0, "V", "s", 2.0, mark_data_type=True).endswith(" D:2.00000      \n")
    assert format_system_row(1.25, "MOOS_DEBUG", "app", "a\nb") == f"{'1.25':<10} {'MOOS_DEBUG':<20} {'app':<20} {'ab':<20} \n"


def test_log_root_name_is_plogger_s() -> None:
    when = time.mktime((2024, 7, 3, 9, 5, 4, 0, 0, -1))
    assert log_root_name("LOG_ALPHA", when) == "LOG_ALPHA_3_7_2024_____09_05_04"
    assert log_root_name("LOG_ALPHA", when, timestamp=False) == "LOG_ALPHA"


# ---- reading --------------------------------------------------------------------------------------------
def test_reads_a_real_plogger_file(tmp_path: Path) -> None:
    (tmp_path / "LOG_ALPHA_28_11_2026_____10_07_44.blog").write_bytes(
        b"2.08585         BIN_V                poker           " + b"\x00\x01abc\n\xff\n")
    path = tmp_path / "real.alog"
    path.write_bytes(REAL_PLOGGER)
    records, reader = read_alog(path)
    assert reader.problems == []
    assert reader.header.logstart == 1795860463.558901
    assert reader.header.log_file is not None and reader.header.log_file.endswith(".alog")
    got = {(r.var, r.time): r.value for r in records}
    assert got[("NAV_X", 2.08573)] == 3.5 and got[("NAV_X", 2.08581)] == -1234567.12346
    assert got[("STR_V", 2.08582)] == "hello world  with  spaces"
    assert got[("EMPTY_S", 2.08583)] == ""
    assert got[("NL_V", 2.08588)] == "line1\nline2"
    assert math.isnan(got[("NAN_V", 2.08591)])  # type: ignore[arg-type]
    summary = got[("DB_VARSUMMARY", 0.65253)]
    assert isinstance(summary, str) and summary.count("\n") == 2 and "connected=pLogger" in summary
    binary = next(r for r in records if r.var == "BIN_V")
    assert binary.is_binary() and reader.read_binary(binary) == b"\x00\x01abc\n\xff"
    assert [r.line for r in records if r.var == "NAV_X"] == [11, 12]


def test_writer_round_trip(tmp_path: Path) -> None:
    path = tmp_path / "ours.alog"
    start = 1_700_000_000.25
    values: list[tuple[str, str, float | str | bytes]] = [
        ("NAV_X", "uSim", 12.5), ("NAV_X", "uSim", -0.000004), ("DEPLOY", "uPokeDB:helm", "true"),
        ("NOTE", "a", "two  inner spaces and a trailing one "), ("EMPTY", "a", ""),
        ("MULTI", "a", "first\nsecond\n"), ("RAW", "a", b"\x00\xffbinary\n"), ("ODD", "a", "caf\udce9"),
        ("BIG", "a", 1e300), ("AFTER", "a", 7.0)]
    with AlogWriter(path, start, header_name="ours.alog") as writer:
        for i, (var, src, value) in enumerate(values):
            writer.write(start + i * 0.5, var, src, value)
    records, reader = read_alog(path)
    assert reader.problems == [] and reader.header.logstart == pytest.approx(start)
    assert [r.var for r in records] == [v[0] for v in values]
    assert [r.time for r in records] == [i * 0.5 for i in range(len(values))]
    by_var = {r.var: r for r in records}
    assert by_var["NAV_X"].value == -0.0  # 5 decimals, as pLogger
    assert by_var["DEPLOY"].source == "uPokeDB:helm" and by_var["DEPLOY"].src == "uPokeDB"
    assert by_var["DEPLOY"].aux == "helm"
    assert by_var["NOTE"].value == "two  inner spaces and a trailing one "
    assert by_var["EMPTY"].value == "" and by_var["MULTI"].value == "first\nsecond\n"
    assert reader.read_binary(by_var["RAW"]) == b"\x00\xffbinary\n"
    assert by_var["ODD"].value == "caf\udce9"  # undecodable bytes come back as the same bytes
    assert by_var["BIG"].value == 1e300 and by_var["AFTER"].value == 7.0
    assert records_to_dicts(records[:1]) == [{"time": 0.0, "var": "NAV_X", "source": "uSim", "value": 12.5}]


def test_data_type_marking_keeps_numeric_strings_strings(tmp_path: Path) -> None:
    path = tmp_path / "marked.alog"
    with AlogWriter(path, 0.0, mark_data_type=True) as writer:
        writer.write(1.0, "COUNT", "a", "42")
        writer.write(2.0, "SPEED", "a", 1.5)
    records, reader = read_alog(path)
    assert reader.header.data_type_marking
    assert [r.value for r in records] == ["42", 1.5]


def test_garbage_and_truncation_are_reported_and_reading_goes_on(tmp_path: Path) -> None:
    body = (
        b"%% LOGSTART        100\n"
        b"garbage before any row\n"
        b"1.000           A                    src             1.00000      \n"
        b"@@@ not a row after a number\n"
        b"2.000           B                    src             text value \n"
        b"3.000           C                    src             2.00000      \n"
        b"4.x             D                    src             3.0 \n"
        b"5.000           E\n"
        b"\n"
        b"6.000           F                    src             \xff\xfe binary junk \n"
        b"7.000           G                    src             4.00"
    )
    path = tmp_path / "bad.alog"
    path.write_bytes(body)
    reader = AlogReader(path)
    records = list(reader)
    assert [(r.var, r.value) for r in records] == [("A", 1.0), ("B", "text value"), ("C", 2.0),
                                                  ("F", "\udcff\udcfe binary junk")]
    problems = {p.line: p.reason for p in reader.problems}
    assert sorted(problems) == [2, 4, 7, 8, 11]
    assert "first column is not a time" in problems[2] and "first column is not a time" in problems[4]
    assert "fewer than three columns" in problems[8]
    assert "truncated last line" in problems[11]
    assert "line 11" in str(reader.problems[-1]) and "4.00" in str(reader.problems[-1])


def test_a_truncated_multi_line_record_is_reported(tmp_path: Path) -> None:
    path = tmp_path / "cut.alog"
    path.write_bytes(b"1.0 A src one\n2.0 B src first line\nsecond li")
    reader = AlogReader(path)
    assert [r.var for r in reader] == ["A"]
    assert [p.line for p in reader.problems] == [2] and "truncated last record" in reader.problems[0].reason


def test_a_continuation_after_a_string_is_joined_unless_asked_not_to() -> None:
    text = b"1.0 A src hello\nworld \n2.0 B src 3\n"
    assert [r.value for r in AlogReader(io.BytesIO(text))] == ["hello\nworld", 3.0]
    strict = AlogReader(io.BytesIO(text), join_continuations=False)
    assert [r.value for r in strict] == ["hello", 3.0] and [p.line for p in strict.problems] == [2]


def test_unreadable_sources_raise_alog_error(tmp_path: Path) -> None:
    with pytest.raises(AlogError, match="cannot read alog"):
        AlogReader(tmp_path / "missing.alog")
    with pytest.raises(AlogError, match="cannot read alog"):
        list(AlogReader(tmp_path))
    with pytest.raises(AlogError, match="float or a str"):
        format_row(0.0, "V", "s", [1])  # type: ignore[arg-type]
    records, _ = read_alog(io.BytesIO(b"1.0 A src x\n"))
    with pytest.raises(AlogError, match="not a binary entry"):
        AlogReader(io.BytesIO(b"")).read_binary(records[0])


def test_to_dataframe_needs_pandas_and_says_so(tmp_path: Path) -> None:
    path = tmp_path / "df.alog"
    with AlogWriter(path, 0.0) as writer:
        writer.write(1.0, "X", "a", 2.0)
    if importlib.util.find_spec("pandas") is None:
        with pytest.raises(AlogError, match="needs pandas"):
            to_dataframe(path)
    else:
        frame = to_dataframe(path)
        assert list(frame.columns) == ["time", "var", "source", "value"] and frame["value"][0] == 2.0


# ---- the real MOOS-IvP tools ------------------------------------------------------------------------------
def test_aloggrep_reads_our_alog(tmp_path: Path) -> None:
    aloggrep = _tool("aloggrep")
    path = tmp_path / "ours.alog"
    with AlogWriter(path, 1_700_000_000.0) as writer:
        writer.write(1_700_000_001.5, "NAV_X", "uSimMarine", 12.25)
        writer.write(1_700_000_002.0, "DEPLOY", "uPokeDB:aux", "true")
        writer.write(1_700_000_002.5, "NAV_X", "uSimMarine", -3.0)
        writer.write(1_700_000_003.0, "OTHER", "x", "not wanted")
    run = subprocess.run([aloggrep, str(path), "NAV_X", "DEPLOY", "--format=time:var:val", "-q"],
                         capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stdout + run.stderr
    rows = [line.split() for line in run.stdout.splitlines() if line.strip() and not line.startswith("%")]
    assert rows == [["1.500", "NAV_X", "12.25000"], ["2.000", "DEPLOY", "true"], ["2.500", "NAV_X", "-3.00000"]]
    by_source = subprocess.run([aloggrep, str(path), "uPokeDB", "--format=val", "-q"],
                               capture_output=True, text=True, timeout=30)
    assert [line.strip() for line in by_source.stdout.splitlines() if line.strip()] == ["true"]


@pytest.mark.parametrize("db", ["ours", "real"])
def test_our_reader_reads_what_the_real_plogger_wrote(db: str, tmp_path: Path) -> None:
    _tool("pLogger")
    if db == "real":
        reason = real_moos_skip_reason("MOOSDB")
        if reason:
            pytest.skip(reason)
    with moosdb_process(tmp_path, community="alpha", program="MOOSDB" if db == "real" else None) as server:
        mission = tmp_path / "plogger.moos"
        mission.write_text(
            f"ServerHost = 127.0.0.1\nServerPort = {server.port}\nCommunity = alpha\n\n"
            "ProcessConfig = pLogger\n{\n  AppTick = 10\n  CommsTick = 10\n  File = REAL\n"
            f"  PATH = {tmp_path}\n  FileTimeStamp = false\n  LogAuxSrc = true\n"
            "  Log = PL_DOUBLE @ 0\n  Log = PL_STRING @ 0\n  Log = PL_BINARY @ 0\n  Log = PL_READY @ 0\n}\n")
        alog = tmp_path / "REAL" / "REAL.alog"  # pLogger makes no parent directories
        with connected_comms(server.port, "poker", ["PL_READY"]) as poker, \
                ChildProcess(["pLogger", str(mission)], tmp_path / "pLogger.log", cwd=tmp_path):
            def logged(var: str) -> bool:
                return alog.exists() and any(r.var == var for r in AlogReader(alog))

            def ready() -> bool:
                poker.notify("PL_READY", 1.0)
                return logged("PL_READY")
            wait_until(ready, 30, "pLogger logging PL_READY", interval=0.2)  # argv[0] names its ProcessConfig
            poker.notify("PL_DOUBLE", 2.5, "aux_info")
            poker.notify("PL_STRING", "hello from poker")
            poker.notify_binary("PL_BINARY", b"\x00\x01\x02\xff")
            poker.notify("PL_DOUBLE", -7.125)
            collect_mail(poker, ["PL_READY"])
            wait_until(lambda: logged("PL_BINARY") and logged("PL_STRING")
                       and [r.var for r in AlogReader(alog)].count("PL_DOUBLE") == 2, 30, "the rows")
    reader = AlogReader(alog)
    records = [r for r in reader if r.var.startswith("PL_") and r.var != "PL_READY"]
    assert reader.problems == []
    assert reader.header.logstart is not None and abs(reader.header.logstart - time.time()) < 120
    assert [(r.var, r.value) for r in records if not r.is_binary()] == [
        ("PL_DOUBLE", 2.5), ("PL_STRING", "hello from poker"), ("PL_DOUBLE", -7.125)]
    assert records[0].source == "poker:aux_info" and records[0].src == "poker"
    binary = next(r for r in records if r.is_binary())
    assert reader.read_binary(binary) == b"\x00\x01\x02\xff"
