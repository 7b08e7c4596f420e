"""Issue #23 items 1-2 for goby-broker, with real sockets and real ZMTP bytes: unfinished frames cannot add up
(a smaller publication frame limit, a cap on connected peers per socket, heartbeats that drop a peer stuck in a
frame), and half-open connections do not lock new clients out (a raised open-files limit, a short handshake time).
"""

from __future__ import annotations

import contextlib
import json
import re
import resource
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from gateway.goby.intervehicle.testing import link_block
from gateway.goby.portal.broker import READY_PREFIX, Broker
from gateway.goby.portal.broker_admission import BrokerLimits
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.portal.testing import BrokerProcess, PortalClient
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from util.process import ChildProcess

MiB = 1024 * 1024
# ZMTP 3.1 greeting: signature, version 3.1, mechanism NULL, as-server 0, filler (RFC 37)
GREETING = b"\xff" + b"\x00" * 8 + b"\x7f" + b"\x03\x01" + b"NULL".ljust(20, b"\x00") + b"\x00" + b"\x00" * 31


def _ready(socket_type: bytes) -> bytes:
    body = b"\x05READY" + b"\x0bSocket-Type" + len(socket_type).to_bytes(4, "big") + socket_type
    return b"\x04" + bytes([len(body)]) + body


def _recv_exactly(sock: socket.socket, n: int) -> bytes:
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("closed")
        data += chunk
    return data


def zmtp_peer(port: int, socket_type: bytes = b"PUB") -> tuple[socket.socket, bool]:
    """A raw ZMTP peer on 127.0.0.1:``port``; True when the broker answered READY (admitted), False on ERROR or
    a closed connection (refused)."""
    sock = socket.create_connection(("127.0.0.1", port), timeout=10)
    sock.sendall(GREETING + _ready(socket_type))
    try:
        _recv_exactly(sock, 64)
        flags, size = _recv_exactly(sock, 2)
        body = _recv_exactly(sock, size)
    except (ConnectionError, OSError):
        return sock, False
    return sock, flags & 0x04 != 0 and body.startswith(b"\x05READY")


def truncated_frame(sock: socket.socket, announced: int, sent: int) -> bool:
    """Announce a frame of ``announced`` bytes and send ``sent`` of them; False if the broker cut us off."""
    assert sent < announced
    try:
        sock.sendall(b"\x02" + announced.to_bytes(8, "big"))
        while sent > 0:
            sock.sendall(b"x" * min(sent, MiB))
            sent -= MiB
    except OSError:
        return False
    return True


def rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise AssertionError("no VmRSS")


def closed_by_peer(sock: socket.socket, timeout: float) -> bool:
    """True once the broker has closed ``sock`` (EOF or reset), reading and discarding what it sends."""
    sock.settimeout(0.2)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if not sock.recv(65536):
                return True
        except TimeoutError:
            continue
        except OSError:
            return True
    return False


def port_of(endpoint: str) -> int:
    return int(endpoint.rsplit(":", 1)[1])


def tcp_cfg(platform: str) -> GobyDaemonConfig:
    cfg = GobyDaemonConfig()
    cfg.interprocess.platform = platform
    cfg.interprocess.transport = InterProcessPortalConfig.TCP
    cfg.interprocess.tcp_port = 0
    return cfg


def client_cfg(broker: Broker) -> InterProcessPortalConfig:
    cfg = InterProcessPortalConfig()
    cfg.CopyFrom(broker.ipc)
    cfg.tcp_port = broker.manager_port
    return cfg


def exchange(cfg: InterProcessPortalConfig, timeout: float = 10.0) -> None:
    """A fresh subscriber and publisher get one message through the broker."""
    with PortalClient(cfg, "fresh_reader") as reader, PortalClient(cfg, "fresh_writer") as writer:
        got = reader.collect("fresh", str)
        assert reader.wait_subscribed(timeout) and writer.wait_ready(timeout)
        deadline = time.monotonic() + timeout
        while not got and time.monotonic() < deadline:  # until our subscription has reached the writer's PUB
            writer.publish("fresh", "hello")
            reader.poll_until(lambda: bool(got), 0.1)
        assert got and got[0] == "hello"


# ----------------------------------------------------------------------------------------- item 1: memory
def test_eight_truncated_60_mb_frames_do_not_grow_the_broker(tmp_path: Path) -> None:
    """The attack as reported: 8 connections, each a 60 MB frame never finished (was +460 MiB RSS)."""
    with BrokerProcess(tmp_path, platform="trunc", tcp=True) as broker:
        pid = broker.endpoints["pid"]
        before = rss_mib(pid)
        peers = []
        try:
            for _ in range(8):
                sock, admitted = zmtp_peer(port_of(broker.endpoints["xsub"]))
                peers.append(sock)
                assert admitted
                truncated_frame(sock, 60 * MiB, 59 * MiB)
            time.sleep(0.5)
            grown = rss_mib(pid) - before
            assert grown < 32, f"broker grew by {grown:.0f} MiB"
            exchange(broker.interprocess_config())
        finally:
            for sock in peers:
                sock.close()


def test_peers_past_max_connections_are_refused_and_a_freed_slot_reopens() -> None:
    limits = BrokerLimits(max_connections=4, max_message_bytes=MiB)
    with Broker(tcp_cfg("cap"), limits=limits) as broker:
        xsub = port_of(broker.endpoints()["xsub"])
        peers = [zmtp_peer(xsub) for _ in range(8)]
        try:
            admitted = [sock for sock, ok in peers if ok]
            # the broker's own manager holds one publisher slot
            assert len(admitted) == limits.max_connections - 1
            for sock in admitted:
                assert truncated_frame(sock, MiB - 100, MiB - 2048)
            assert all(closed_by_peer(sock, 5) for sock, ok in peers if not ok)
        finally:
            for sock, _ in peers:
                sock.close()
        # the slots come back once the peers are gone: ZeroMQ retries a refused client every 100 ms
        exchange(client_cfg(broker), timeout=15)


def test_a_peer_stuck_in_a_frame_is_dropped_by_the_heartbeat() -> None:
    limits = BrokerLimits(heartbeat_s=0.2, heartbeat_timeout_s=1.0)
    with Broker(tcp_cfg("stuck"), limits=limits) as broker:
        sock, admitted = zmtp_peer(port_of(broker.endpoints()["xsub"]))
        with sock:
            assert admitted
            assert truncated_frame(sock, 2 * MiB, MiB)
            assert closed_by_peer(sock, 6), "a peer holding half a frame stayed connected"
        exchange(client_cfg(broker))


# ---------------------------------------------------------------------------------- item 2: half-open flood
@contextlib.contextmanager
def broker_with_open_files(tmp_path: Path, soft: int, hard: int | None) -> Iterator[dict[str, object]]:
    """goby-broker (TCP) started with RLIMIT_NOFILE (soft, hard); yields its ready line's endpoints."""
    hard_text = "h" if hard is None else str(hard)
    wrapper = ("import resource, sys\n"
               "s, h = resource.getrlimit(resource.RLIMIT_NOFILE)\n"
               f"resource.setrlimit(resource.RLIMIT_NOFILE, ({soft}, {hard_text}))\n"
               "from gateway.apps.goby_broker import main\n"
               "sys.exit(main(sys.argv[1:]))\n")
    args = [sys.executable, "-c", wrapper, "--interprocess", 'platform: "flood" transport: TCP tcp_port: 0']
    with ChildProcess(args, tmp_path / "broker.log", name="goby-broker (flood)",
                      cwd=Path(__file__).resolve().parents[2]) as child:
        ready = child.start().wait_ready(re.escape(READY_PREFIX) + "(.*)", timeout=30)
        assert ready is not None
        yield json.loads(ready.group(1))


@contextlib.contextmanager
def half_open(port: int, count: int) -> Iterator[list[socket.socket]]:
    """``count`` connections to ``port`` that never send a byte."""
    socks: list[socket.socket] = []
    try:
        for _ in range(count):
            try:
                socks.append(socket.create_connection(("127.0.0.1", port), timeout=2))
            except OSError:  # the listen backlog is full: the broker is not accepting any more
                break
        yield socks
    finally:
        for sock in socks:
            sock.close()


@pytest.fixture
def many_files() -> Iterator[None]:
    """This test process needs more than 2,200 descriptors of its own."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if hard != resource.RLIM_INFINITY and hard < 4096:
        pytest.skip(f"open-files hard limit {hard} is too small for the flood")
    resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, 4096), hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))


def _flood_then_join(endpoints: dict[str, object], within: float) -> float:
    manager, xsub = port_of(str(endpoints["manager"])), port_of(str(endpoints["xsub"]))
    cfg = InterProcessPortalConfig(platform="flood", transport=InterProcessPortalConfig.TCP, tcp_port=manager,
                                   manager_timeout_seconds=int(within))
    with half_open(manager, 1078), half_open(xsub, 1078):
        time.sleep(0.5)  # let the broker accept what it can
        start = time.monotonic()
        exchange(cfg, timeout=within)
        return time.monotonic() - start


def test_half_open_flood_does_not_lock_new_clients_out(tmp_path: Path, many_files: None) -> None:
    """At the usual soft limit of 1024 descriptors, 2 x 1,078 silent connections filled the table and locked new
    clients out for ZeroMQ's 30 s handshake time; the broker now raises its soft limit to the hard one."""
    with broker_with_open_files(tmp_path, 1024, None) as endpoints:
        assert _flood_then_join(endpoints, 5) < 5


def test_half_open_flood_at_a_hard_descriptor_limit_clears_within_the_handshake_time(
        tmp_path: Path, many_files: None) -> None:
    """Where the hard limit is 1024 too, the silent connections are closed after ``handshake_s`` (3 s), not 30 s."""
    with broker_with_open_files(tmp_path, 1024, 1024) as endpoints:
        elapsed = _flood_then_join(endpoints, 15)
        assert elapsed < 15


def test_a_broker_refuses_bad_limits() -> None:
    with pytest.raises(ValueError, match="max_connections"):
        BrokerLimits(max_connections=0)
    with pytest.raises(ValueError, match="heartbeat_s"):
        BrokerLimits(heartbeat_s=float("nan"))


# ------------------------------------------------------------------------------------ items 3-4: bad config
_LINK = link_block(1, "239.255.7.7", 50999, [(1, 1.0, 64)])


@pytest.mark.parametrize("text, named", [
    ('interprocess { transport: TCP tcp_port: 99999 }', "interprocess.tcp_port: 99999 is not a port number"),
    ("intervehicle { " + _LINK.replace("multicast_port: 50999", "multicast_port: 70000") + " }",
     "intervehicle.link[0].driver.[goby.acomms.udp_multicast.protobuf.config].multicast_port: 70000"),
    ("app { simulation { time { use_sim_time: true warp_factor: -3 } } }\nintervehicle { " + _LINK + " }",
     "app.simulation.time.warp_factor: -3 must be a finite number > 0"),
    ("app { simulation { time { warp_factor: 0 } } }", "app.simulation.time.warp_factor: 0"),
    (b"\x00\x9f\x92\x96garbage\xff\xfe", "line 1: not protobuf text format (byte 0x9f at offset 1"),
])
def test_a_bad_config_is_one_line_naming_the_field_and_exit_2(tmp_path: Path, text: str | bytes, named: str) -> None:
    path = tmp_path / "gobyd.pb.cfg"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text + f'\ninterprocess {{ platform: "bad" socket_name: "{tmp_path}/b" }}\n'
                        if "interprocess" not in text else text)
    done = subprocess.run([sys.executable, "-m", "gateway.apps.goby_broker", str(path)], capture_output=True,
                          text=True, timeout=20, cwd=Path(__file__).resolve().parents[2])
    assert done.returncode == 2, done.stderr
    assert done.stderr.splitlines() == [f"goby-broker: configuration error: {done.stderr.split(': ', 2)[2].strip()}"]
    assert named in done.stderr and "Traceback" not in done.stderr
