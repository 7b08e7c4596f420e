"""The real Goby3 3.1 log tools and ours on each other's logs.  Skipped with the reason unless goby_logger,
goby_log_tool and gobyd are on PATH inside a private network namespace (tests/goby3_real.py)::

    unshare -rn bash -c 'ip link set lo up && exec "$@"' _ env PATH=/work/cpp/prefix/bin:$PATH \\
        LD_LIBRARY_PATH=/work/cpp/prefix/lib .venv/bin/python -m pytest -q tests/goby_log/test_interop.py
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

from gateway.goby.log.protobuf.logger_pb2 import LoggerRequest
from gateway.goby.portal import Scheme
from gateway.goby.portal.testing import PortalClient, app_process, broker_process
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from tests.goby3_real import interprocess_text, real_goby_skip_reason, short_ipc_dir
from tests.goby_log.test_apps import logged, publish_traffic, start_logger, wait_logging

pytestmark = pytest.mark.interop
PY = sys.executable


def real_debug_text(tmp_path: Path, log: Path, name: str) -> list[str]:
    out = tmp_path / f"{name}.txt"
    tool = app_process(["goby_log_tool", str(log), str(out), "--format", "DEBUG_TEXT"], tmp_path / f"{name}.log")
    assert tool.wait(60) == 0, tool.tail()
    return out.read_text().splitlines()


def our_debug_text(tmp_path: Path, log: Path, name: str) -> list[str]:
    out = tmp_path / f"{name}.txt"
    tool = app_process([PY, "-m", "gateway.apps.goby_log_tool", str(log), str(out)], tmp_path / f"{name}.log")
    assert tool.wait(60) == 0, tool.tail()
    return out.read_text().splitlines()


def test_real_goby_log_tool_reads_our_log(tmp_path: Path) -> None:
    reason = real_goby_skip_reason("goby_log_tool")
    if reason:
        pytest.skip(reason)
    latest = tmp_path / "ours_latest.goby"
    with broker_process(tmp_path, platform="ours") as broker:
        logger = start_logger(tmp_path, broker, tmp_path)
        try:
            with PortalClient(broker.interprocess_config(), "publisher") as client:
                wait_logging(client, latest)
                sent = publish_traffic(client)
                assert client.poll_until(lambda: len(logged(latest)) == len(sent), 30)
        finally:
            assert logger.stop() == 0, logger.tail()
    real = real_debug_text(tmp_path, latest, "real")
    ours = our_debug_text(tmp_path, latest, "ours")
    assert len(real) == len(ours) >= len(sent)
    for theirs, mine in zip(real, ours, strict=True):
        assert theirs.split(" | ")[:4] == mine.split(" | ")[:4]  # scheme, group, type, time: the same entries
        if not theirs.startswith(f"{Scheme.CSTR} |"):  # CSTR: Goby has no plugin and prints "Unable to parse"
            assert theirs == mine
    # the real tool decoded our test types from the descriptors our logger wrote (it has no code for them)
    assert any(line.startswith("1 | nav | goby.test.zeromq.protobuf.Sample |") and line.endswith("| a: 4 depth: 2 "
               'padding: "s4"') for line in real)


def test_our_log_tool_reads_a_real_goby_logger_log(tmp_path: Path) -> None:
    reason = real_goby_skip_reason("gobyd", "goby_logger", "goby_log_tool")
    if reason:
        pytest.skip(reason)
    ipc_dir = short_ipc_dir()
    ipc = InterProcessPortalConfig(platform="real", socket_name=str(ipc_dir / "goby_real"))
    gobyd = app_process(["gobyd", "--interprocess", interprocess_text(ipc)], tmp_path / "gobyd.log")
    logger = app_process(["goby_logger", "--log_dir", str(tmp_path), "--interprocess", interprocess_text(ipc)],
                         tmp_path / "goby_logger.log")
    latest = tmp_path / "real_latest.goby"
    try:
        with PortalClient(ipc, "publisher") as client:
            assert client.wait_ready()
            # goby_logger writes through a buffered ofstream: the file shows entries only in 4 KiB steps, so
            # publish until one sync entry is on disk (the subscription is in place), then the test entries
            sync = 0
            while not logged(latest, ("sync",)):
                assert sync < 3000, logger.tail()
                client.publish("sync", f"ping {sync}")
                client.poll(0.01)
                sync += 1
            for i in range(5):
                state = LoggerRequest.ROTATE_LOG if i % 2 else LoggerRequest.STOP_LOGGING
                client.publish("test::request", LoggerRequest(requested_state=state))
                client.publish("test::text", f"line {i}")
            client.poll(1.0)
        assert logger.stop() == 0, logger.tail()  # closing flushes the file
    finally:
        logger.stop()
        gobyd.stop()
        shutil.rmtree(ipc_dir, ignore_errors=True)
    assert len(logged(latest, ("test::request", "test::text"))) == 10
    real = real_debug_text(tmp_path, latest, "real")
    ours = our_debug_text(tmp_path, latest, "ours")
    assert len(real) == len(ours) > 10
    for theirs, mine in zip(real, ours, strict=True):
        if theirs.startswith(f"{Scheme.CSTR} |"):
            assert theirs.split(" | ")[:4] == mine.split(" | ")[:4]
        else:
            assert theirs == mine
    assert sum("| goby.middleware.protobuf.LoggerRequest |" in line for line in ours) == 5
    assert "0 | test::text | CSTR |" in "\n".join(ours) and ours[-1].endswith("| line 4")
