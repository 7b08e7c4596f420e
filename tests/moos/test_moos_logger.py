"""``moos-logger`` as a process on a MOOSDB process (ours; the real one inside a private network namespace), poked
by a client, its files read back with gateway.moos.alog and, when present, the real ``aloggrep``."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from gateway.apps.moos_logger import LoggerConfig, LogRequest
from gateway.moos.alog import AlogReader, AlogRecord
from gateway.moos.mission_file import MissionFile
from gateway.moos.testing import MoosDBProcess, connected_comms, real_moos_skip_reason
from util.process import ChildProcess, wait_until

REPO = Path(__file__).resolve().parents[2]
ROOT = re.compile(r"LOG_ALPHA_\d{1,2}_\d{1,2}_\d{4}_____\d\d_\d\d_\d\d")


@pytest.fixture(params=["ours", "real"])
def db(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[MoosDBProcess]:
    """A MOOSDB process: our moos-db, and the real MOOSDB when it may run here."""
    program = None
    if request.param == "real":
        reason = real_moos_skip_reason("MOOSDB")
        if reason:
            pytest.skip(reason)
        program = "MOOSDB"
    with MoosDBProcess(tmp_path, community="alpha", program=program) as server:
        yield server


def _mission(tmp_path: Path, port: int, block: str) -> Path:
    path = tmp_path / "logger.moos"
    path.write_text(f"ServerHost = 127.0.0.1\nServerPort = {port}\nCommunity = alpha\n\n"
                    f"ProcessConfig = pLogger\n{{\n  AppTick = 20\n{block}}}\n")
    return path


def _logger(tmp_path: Path, mission: Path) -> ChildProcess:
    env = dict(os.environ, PYTHONPATH=str(REPO))
    return ChildProcess([sys.executable, "-m", "gateway.apps.moos_logger", str(mission), "-v"],
                        tmp_path / "moos-logger.log", env=env, cwd=tmp_path)


def _records(alog: Path) -> list[AlogRecord]:
    return list(AlogReader(alog)) if alog.exists() else []


def test_logger_writes_plogger_files_that_read_back(db: MoosDBProcess, tmp_path: Path) -> None:
    mission = _mission(tmp_path, db.port, f"  File = LOG_ALPHA\n  PATH = {tmp_path}/logs/\n  LogAuxSrc = true\n"
                       "  Log = NAV_X @ 0\n  Log = NAV_Y @ 0 NOSYNC\n  Log = READY @ 0\n  Log = RAW @ 0\n"
                       "  Log = NOTE @ 0\n")
    with connected_comms(db.port, "poker") as poker, _logger(tmp_path, mission) as logger:
        found = logger.wait_ready(r"logging to (\S+)", timeout=30)
        assert found is not None
        directory = Path(found.group(1))
        assert directory.parent == tmp_path / "logs" and ROOT.fullmatch(directory.name)
        alog = directory / f"{directory.name}.alog"

        def ready() -> bool:
            poker.notify("READY", 1.0)
            return any(r.var == "READY" for r in _records(alog))
        wait_until(ready, 30, "moos-logger logging READY", interval=0.2)
        poker.notify("NAV_X", 10.5, "nav_aux")
        poker.notify("NAV_Y", -3.25)
        poker.notify("NOTE", "two  words\nand a line ")
        poker.notify_binary("RAW", b"\x00\x01\xfe\xff")
        poker.notify("UNLOGGED", "nobody asked")
        poker.notify("NAV_X", 11.0)
        wait_until(lambda: [r.var for r in _records(alog)].count("NAV_X") == 2, 30, "the rows")
    assert logger.returncode == 0, logger.tail()
    reader = AlogReader(alog)
    records = [r for r in reader if r.var != "READY"]
    assert reader.problems == []
    assert reader.header.log_file == f"{tmp_path}/logs/{directory.name}/{directory.name}.alog"
    assert [(r.var, r.value) for r in records if not r.is_binary()] == [
        ("NAV_X", 10.5), ("NAV_Y", -3.25), ("NOTE", "two  words\nand a line "), ("NAV_X", 11.0)]
    assert records[0].source == "poker:nav_aux" and records[1].source == "poker"
    assert all(0 < r.time < 120 for r in records)
    binary = next(r for r in records if r.is_binary())
    assert reader.read_binary(binary) == b"\x00\x01\xfe\xff"
    copy = (directory / f"{directory.name}._moos").read_text()
    assert copy.startswith("%%%%") and copy.endswith(mission.read_text() + "\n")
    assert (directory / f"{directory.name}.ylog").read_text().startswith("%%%%")
    assert (tmp_path / ".LastOpenedMOOSLogDirectory").read_text() == f"LastOpenedLoggingDirectory={directory}\n"
    aloggrep = shutil.which("aloggrep")
    if aloggrep:  # the real MOOS-IvP tool finds our rows
        run = subprocess.run([aloggrep, str(alog), "NAV_X", "-q"], capture_output=True, text=True, timeout=30)
        rows = [line.split() for line in run.stdout.splitlines() if line.strip() and not line.startswith("%")]
        assert [row[1:] for row in rows] == [["NAV_X", "poker:nav_aux", "10.50000"], ["NAV_X", "poker", "11.00000"]]


def test_wildcard_logging_with_omit_patterns_and_commands(db: MoosDBProcess, tmp_path: Path) -> None:
    mission = _mission(tmp_path, db.port, f"  File = WILD\n  PATH = {tmp_path}\n  FileTimeStamp = false\n"
                       "  WildCardLogging = true\n  WildCardOmitPattern = *_STATUS, SECRET_*\n"
                       "  MarkExternalCommunityMessages = true\n")
    alog = tmp_path / "WILD" / "WILD.alog"
    with connected_comms(db.port, "poker") as poker, _logger(tmp_path, mission) as logger:
        logger.wait_ready(r"logging to", timeout=30)

        def ready() -> bool:
            poker.notify("WILD_READY", 1.0)
            return any(r.var == "WILD_READY" for r in _records(alog))
        wait_until(ready, 30, "moos-logger logging WILD_READY", interval=0.2)
        for i in range(3):
            poker.notify("FRESH_VAR", float(i))
        poker.notify("APP_STATUS", "omitted")
        poker.notify("SECRET_KEY", "omitted")
        poker.notify("LAST_VAR", "done")
        wait_until(lambda: any(r.var == "LAST_VAR" for r in _records(alog)), 30, "LAST_VAR")
    assert logger.returncode == 0, logger.tail()
    records = _records(alog)
    names = {r.var for r in records}
    assert [r.value for r in records if r.var == "FRESH_VAR"] == [0.0, 1.0, 2.0]  # from the first posting on
    assert "APP_STATUS" not in names and "SECRET_KEY" not in names
    assert "LOGGER_DIRECTORY" in names  # its own posting, as pLogger logs it
    assert all("@" not in r.source for r in records if r.var == "FRESH_VAR")  # same community: no mark


def test_an_unwritable_path_stops_with_one_line(tmp_path: Path) -> None:
    blocker = tmp_path / "not_a_directory"
    blocker.write_text("a file")
    mission = _mission(tmp_path, 9, f"  PATH = {blocker}\n  Log = X @ 0\n")
    with _logger(tmp_path, mission) as logger:
        assert logger.wait(30) == 1
    text = logger.output()
    assert "cannot create the log directory" in text and str(blocker) in text
    assert "Traceback" not in text


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full to fill")
def test_a_full_disk_stops_with_one_line(db: MoosDBProcess, tmp_path: Path) -> None:
    (tmp_path / "FULL").mkdir()
    (tmp_path / "FULL" / "FULL.alog").symlink_to("/dev/full")  # every write: ENOSPC
    mission = _mission(tmp_path, db.port, f"  File = FULL\n  PATH = {tmp_path}\n  FileTimeStamp = false\n"
                       "  Log = X @ 0\n")
    with _logger(tmp_path, mission) as logger:
        assert logger.wait(30) == 1
    text = logger.output()
    assert "No space left on device" in text and "Traceback" not in text


def test_config_is_read_as_plogger_reads_it(tmp_path: Path) -> None:
    assert LogRequest.parse("NAV_X @ 0.5 NOSYNC") == LogRequest("NAV_X", 0.5)
    assert LogRequest.parse("NAV_X") == LogRequest("NAV_X", 2.0)  # pLogger's default period
    assert LogRequest.parse("NAV_X @ 0, MONITOR") == LogRequest("NAV_X", 0.0, True)
    assert LogRequest.parse(" @ 1") is None
    mission = MissionFile.from_text(
        "GlobalLogPath = /data/logs\nProcessConfig = pLogger\n{\n  log = A @ 1\n  Log = A @ 5\n"
        "  WILDCARDLOGGING = 1\n  WildCardPattern = NAV_*,DESIRED_*\n  LogAuxSrc = yes\n  AsyncLog = false\n"
        "  DoublePrecision = 3\n  FileTimeStamp = FALSE\n  SyncLog = true @ 0.2\n}\n")
    cfg = LoggerConfig.from_mission(mission, "pLogger")
    assert cfg.logs == [LogRequest("A", 1.0)]  # the first request for a variable wins
    assert cfg.wildcard and cfg.async_log  # wildcard logging turns the alog on
    assert cfg.accept == ["NAV_*", "DESIRED_*"] and cfg.omit == ["MISSION_FILE"]
    assert not cfg.log_aux_src and not cfg.file_timestamp  # libMOOS: TRUE or a number > 0
    assert cfg.double_precision == 3 and cfg.path == "/data/logs"
    assert cfg.wildcard_wants("NAV_X") and not cfg.wildcard_wants("MISSION_FILE") and not cfg.wildcard_wants("X")
    assert any("SyncLog" in text for text in cfg.unsupported)
    assert LoggerConfig.from_mission(MissionFile.from_text("Community = a\n"), "pLogger").wildcard
