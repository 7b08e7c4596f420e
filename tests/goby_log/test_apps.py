"""goby-logger, goby-log-tool and goby-playback as processes on our broker: bytes in, the same bytes out."""

from __future__ import annotations

import json
import os
import stat
import sys
import time
from pathlib import Path

from gateway.goby.log import LogReader, bson
from gateway.goby.portal import Scheme
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process, broker_process
from tests.goby_log.test_format import record, sample_log
from tests.protobuf.sample_messages_pb2 import DCCLSample, Sample
from util.process import ChildProcess

PY = sys.executable
OURS = ("nav", "text", "json", "dccl")


def start_logger(tmp_path: Path, broker: BrokerProcess, log_dir: Path, *extra: str) -> ChildProcess:
    """The logger imports the test messages (load_shared_library), so their descriptors go into the log."""
    return app_process([PY, "-m", "gateway.apps.goby_logger", "--log_dir", str(log_dir),
                        "--load_shared_library", "tests.protobuf.sample_messages_pb2",
                        "--interprocess", broker.interprocess_text(), *extra], tmp_path / "logger.log")


def logged(path: Path, groups: tuple[str, ...] = OURS) -> list[tuple[str, int, str, bytes]]:
    if not path.exists():
        return []
    with LogReader(path, on_skip=lambda span: None) as reader:
        return [(e.group, e.scheme, e.type_name, e.data) for e in reader if e.group in groups]


def wait_logging(client: PortalClient, path: Path) -> None:
    """Publish on "sync" until the logger has written one: its regex subscription is in place."""
    assert client.wait_ready()
    deadline = time.monotonic() + 30
    while not logged(path, ("sync",)):
        assert time.monotonic() < deadline, "the logger never logged the sync group"
        client.publish("sync", "ping")
        client.poll(0.1)


def publish_traffic(client: PortalClient) -> list[tuple[str, int, str, bytes]]:
    """Every scheme once or more; returns what a log of it must hold, in order."""
    sent: list[tuple[str, int, str, bytes]] = []
    for i in range(5):
        msg = Sample(a=i, depth=i * 0.5, padding=f"s{i}".encode())
        client.publish("nav", msg)
        sent.append(("nav", Scheme.PROTOBUF, Sample.DESCRIPTOR.full_name, msg.SerializeToString()))
        client.publish("text", f"line {i}")
        sent.append(("text", Scheme.CSTR, "CSTR", f"line {i}\0".encode()))
    doc = bson.encode({"depth": 12.5, "name": "auv"})
    client.portal.publish_serialized("json", Scheme.JSON, "nlohmann::json", doc)
    sent.append(("json", Scheme.JSON, "nlohmann::json", doc))
    dccl = DCCLSample(a=42)
    client.publish("dccl", dccl, scheme=Scheme.DCCL)
    sent.append(("dccl", Scheme.DCCL, DCCLSample.DESCRIPTOR.full_name, client.context.dccl.encode(dccl)))
    return sent


def test_logger_log_tool_and_playback_round_trip(tmp_path: Path) -> None:
    log_dir = tmp_path / "logs"
    log_dir.mkdir()
    latest = log_dir / "lg_latest.goby"
    with broker_process(tmp_path, platform="lg") as broker:
        logger = start_logger(tmp_path, broker, log_dir)
        try:
            with PortalClient(broker.interprocess_config(), "publisher") as client:
                wait_logging(client, latest)
                sent = publish_traffic(client)
                assert client.poll_until(lambda: len(logged(latest)) == len(sent), 30), logger.tail()
        finally:
            assert logger.stop() == 0, logger.tail()
    assert logged(latest) == sent
    [real] = [p for p in log_dir.iterdir() if not p.is_symlink()]
    assert latest.resolve() == real.resolve()
    assert real.name.startswith("lg_2") and len(real.stem) == len("lg_YYYYMMDDTHHMMSS")
    assert stat.S_IMODE(real.stat().st_mode) == 0o440  # read-only once closed, as Goby leaves it

    # goby-log-tool: DEBUG_TEXT and JSON, default output names in the working directory
    for fmt in ("DEBUG_TEXT", "JSON"):
        tool = app_process([PY, "-m", "gateway.apps.goby_log_tool", str(real), "--format", fmt],
                           tmp_path / f"tool_{fmt}.log", cwd=tmp_path)
        assert tool.wait(60) == 0, tool.tail()
    text = (tmp_path / (real.stem + ".txt")).read_text().splitlines()
    ours = [line for line in text if line.split(" | ")[1] in OURS]
    assert [tuple(line.split(" | ")[:3]) for line in ours] == [(str(s), g, t) for g, s, t, _ in sent]
    assert ours[4].endswith("| a: 2 depth: 1 padding: \"s2\"") and ours[5].endswith("| line 2")
    assert ours[-2].endswith('| {"depth":12.5,"name":"auv"}') and ours[-1].endswith("| a: 42")
    objects = [json.loads(line) for line in (tmp_path / (real.stem + ".json")).read_text().splitlines()]
    mine = [o for o in objects if o["_group_"] in OURS]
    assert [o["_group_"] for o in mine] == [g for g, *_ in sent]
    assert mine[0]["_type_"] == Sample.DESCRIPTOR.full_name and mine[2]["depth"] == 0.5
    assert mine[-2]["depth"] == 12.5 and mine[-1]["a"] == 42

    # goby-playback into a fresh broker: same groups, types, payloads, order
    with broker_process(tmp_path, platform="pb") as fresh, PortalClient(fresh.interprocess_config(), "rx") as rx:
        got: list[tuple[str, int, str, bytes]] = []
        rx.portal.subscribe_regex(lambda data, scheme, tname, group: got.append((group, scheme, tname, data)))
        assert rx.wait_subscribed()
        playback = app_process([PY, "-m", "gateway.apps.goby_playback", str(real), "--rate", "4",
                                "--playback_start_delay", "1", "--interprocess", fresh.interprocess_text()],
                               tmp_path / "playback.log")
        try:
            assert rx.poll_until(lambda: len([g for g in got if g[0] in OURS]) == len(sent), 60), playback.tail()
            assert playback.wait(30) == 0, playback.tail()
        finally:
            playback.stop()
    assert [g for g in got if g[0] in OURS] == sent
    assert not any(g[0].startswith("goby::log::") for g in got)  # descriptor entries are not replayed


def test_killed_logger_leaves_a_readable_log(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="kl") as broker:
        logger = start_logger(tmp_path, broker, tmp_path, "--omit", "file_timestamp: true")
        path = tmp_path / "kl.goby"
        with PortalClient(broker.interprocess_config(), "publisher") as client:
            wait_logging(client, path)
            for i in range(3000):
                client.publish("nav", Sample(a=i, padding=b"x" * 200))
                if i % 100 == 99:
                    client.poll(0.01)
            client.poll_until(lambda: len(logged(path)) > 100, 30)
            logger.kill()
    with LogReader(path, on_skip=lambda span: None) as reader:
        values = [Sample.FromString(e.data).a for e in reader if e.group == "nav"]
        spans = reader.skipped
    # every entry on disk is whole and in order (a burst may overflow a ZeroMQ queue: that is the transport's)
    assert values == sorted(set(values)) and len(values) > 100
    assert spans == [] or (len(spans) == 1 and spans[0].offset + spans[0].length == path.stat().st_size)


def test_unwritable_log_dir_and_full_disk_stop_with_one_line(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="fd") as broker:
        missing = start_logger(tmp_path, broker, tmp_path / "no" / "such" / "dir")
        assert missing.wait(30) == 1
        err = (tmp_path / "logger.log").read_text()
        assert "Failed to open log in directory" in err and "Traceback" not in err

        full_dir = tmp_path / "full"
        full_dir.mkdir()
        os.symlink("/dev/full", full_dir / "fd.goby")  # every write: ENOSPC
        full = app_process([PY, "-m", "gateway.apps.goby_logger", "--log_dir", str(full_dir), "--interprocess",
                            broker.interprocess_text(), "--omit", "file_timestamp: true latest_symlink: true"],
                           tmp_path / "full.log")
        with PortalClient(broker.interprocess_config(), "publisher") as client:
            assert client.wait_ready()
            assert client.poll_until(lambda: (client.publish("x", "y"), full.poll())[1] is not None, 30)
        assert full.wait(10) == 1
        err = (tmp_path / "full.log").read_text()
        assert "No space left on device" in err and "Traceback" not in err
        assert sum("No space left" in line for line in err.splitlines()) == 1


def test_log_tool_reports_damage_by_offset_and_exit_code(tmp_path: Path) -> None:
    whole = sample_log()
    entries = list(LogReader(whole))
    at = entries[2].offset
    damaged = tmp_path / "damaged.goby"
    damaged.write_bytes(whole[:at] + b"garbage!" + whole[at:] + record(0x0099, 1, 1, 0, b"??") + whole[:-3][-10:])
    tool = app_process([PY, "-m", "gateway.apps.goby_log_tool", str(damaged), "-"], tmp_path / "damaged.log")
    assert tool.wait(60) == 3
    err = (tmp_path / "damaged.log").read_text()
    assert f"skipped 8 byte(s) at offset {at}" in err and "unknown scheme 153" in err and "Traceback" not in err
    assert len(tool.lines()) == len(entries)  # every entry is still there

    clean = tmp_path / "clean.goby"
    clean.write_bytes(whole)
    tool = app_process([PY, "-m", "gateway.apps.goby_log_tool", "-i", str(clean), "-o", "-", "--format", "JSON"],
                       tmp_path / "clean.log")
    assert tool.wait(60) == 0 and len(tool.lines()) == len(entries)

    newer = tmp_path / "newer.goby"
    newer.write_bytes(b"\x00\x00\x00\x04" + whole[4:])
    tool = app_process([PY, "-m", "gateway.apps.goby_log_tool", str(newer)], tmp_path / "newer.log", cwd=tmp_path)
    assert tool.wait(60) == 1
    assert "version 4 is newer" in (tmp_path / "newer.log").read_text()
