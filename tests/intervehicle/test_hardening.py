"""Issue 23 on the intervehicle links: one datagram must never take a link down, a failed link thread is reported
and restarted, links hear only their group on their interface from their peers, bad settings are named errors.

Real sockets and processes throughout; the "second host" is a network namespace joined by a veth pair."""

from __future__ import annotations

import logging
import os
import re
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from google.protobuf import text_format

from gateway.goby.acomms.ether import Ether, EtherDriver
from gateway.goby.acomms.protobuf.amac_config_pb2 import MAC_FIXED_DECENTRALIZED
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission
from gateway.goby.acomms.udp_multicast import join_multicast, random_multicast
from gateway.goby.dccl import Codec
from gateway.goby.intervehicle import Publisher, Subscriber, TransporterConfig
from gateway.goby.intervehicle.portal import IntervehiclePortal
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import PortalConfig
from gateway.goby.intervehicle.testing import IntervehicleClient, LoopbackLink, link_block, link_brokers
from gateway.goby.portal import Group
from gateway.goby.portal.broker import READY_PREFIX
from gateway.goby.portal.context import ProcessContext
from gateway.goby.portal.testing import broker_process, poll_all
from gateway.goby.portal.timeutil import SystemClock
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from tests.markers import needs_loopback_multicast
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from util.process import ChildProcess, wait_until
from util.ratelimit import RateLimitedLog

WARP = 20
SAT = [(1, 5, 64), (2, 5, 64)]
usv_command = Group("usv_command", 0)


def send_multicast(datagram: bytes, group: str, port: int) -> None:
    """One datagram to ``group:port`` on loopback, as another node on the machine would send it."""
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
        tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        tx.sendto(datagram, (group, port))
    finally:
        tx.close()


def drain(tap: socket.socket) -> list[ModemTransmission]:
    """Every ModemTransmission waiting on the non-blocking ``tap``."""
    heard = []
    while True:
        try:
            heard.append(ModemTransmission.FromString(tap.recv(65535)))
        except BlockingIOError:
            return heard
        except Exception:  # noqa: BLE001 - the poison itself
            continue


def command_subscriber(client: IntervehicleClient, received: list[USVCommand], on_subscribed=None) -> None:
    """Subscribe ``client`` to USVCommand from the topside (modem 1), acked."""
    cfg = TransporterConfig()
    cfg.intervehicle.publisher_id.append(1)
    cfg.intervehicle.buffer.ack_required = True
    client.intervehicle().subscribe(usv_command, USVCommand, received.append,
                                    Subscriber(cfg=cfg, on_subscribed=on_subscribed))


# -- 1. the poison datagram ---------------------------------------------------------------------------------


@needs_loopback_multicast
def test_poison_datagrams_leave_the_link_carrying_traffic(tmp_path: Path) -> None:
    sat = LoopbackLink(SAT)
    tap = join_multicast(sat.group, sat.port, "127.0.0.1")  # every datagram on the link, to check the acks
    tap.setblocking(False)
    links = {"topside": [sat.block(1)], "usv": [sat.block(2)]}
    heard: list[ModemTransmission] = []
    try:
        with link_brokers(tmp_path, links, "poison", warp=WARP) as brokers:
            poison = ModemTransmission(src=1, dest=2, type=ModemTransmission.DATA, ack_requested=True,
                                       frame_start=2**32 - 1)
            poison.frame.append(b"\x01")
            wide = ModemTransmission(src=1, dest=2, type=ModemTransmission.DATA, ack_requested=True)
            wide.frame.extend([b""] * 20_000)
            acks = ModemTransmission(src=1, dest=2, type=ModemTransmission.ACK)
            acks.acked_frame.extend(range(5000))
            for datagram in (poison, wide, acks, poison):
                send_multicast(datagram.SerializeToString(), sat.group, sat.port)
            usv_log = brokers["usv"].stderr_text
            wait_until(lambda: "20000 frames" in usv_log() and "frame_start 4294967295" in usv_log(), 10,
                       "the USV's link to refuse both poison datagrams")
            for _ in range(200):  # a flood of garbage: one line, then counts
                send_multicast(b"\xff\xfe not a ModemTransmission", sat.group, sat.port)
            wait_until(lambda: "not a ModemTransmission" in usv_log(), 10, "the garbage to be refused")
            heard = drain(tap)  # (before its buffer fills)
            topside = IntervehicleClient(brokers["topside"].interprocess_config(), "topside_app")
            usv = IntervehicleClient(brokers["usv"].interprocess_config(), "usv_app")
            try:
                assert topside.wait_subscribed() and usv.wait_subscribed()
                received: list[USVCommand] = []
                subscribed: list[int] = []
                command_subscriber(usv, received, lambda s, a: subscribed.append(1))
                assert poll_all([topside, usv], lambda: subscribed, 20), brokers["usv"].stderr_text()
                acked: list[int] = []
                command = USVCommand(time=time.time(), desired_state=USVCommand.WAYPOINTS)
                topside.intervehicle().publish(usv_command, command,
                                               Publisher(on_ack=lambda m, a: acked.append(a.header.src)))
                assert poll_all([topside, usv], lambda: acked and received, 15), brokers["usv"].stderr_text()
            finally:
                topside.close()
                usv.close()
            text = usv_log()
            assert "Traceback" not in text and "failed" not in text, text
            assert re.search(r"link 2: dropping a datagram .*: from modem 1: 20000 frames, more than the 1 a slot",
                             text), text
            assert "5000 acked frames" in text and "not a ModemTransmission" in text
        # the two poison frames with frame_start 2^32-1: one line, then the count on shutdown (rate-limited)
        text = brokers["usv"].stderr_text()
        lines = [line for line in text.splitlines() if "frame_start 4294967295" in line]
        assert len(lines) == 2 and "(the latest of 1 like this" in lines[1], text
        garbage = [line for line in text.splitlines() if "not a ModemTransmission" in line]
        assert len(garbage) <= 2, garbage
        read = int(re.findall(r"\[malformed: (\d+) dropped so far\]", garbage[-1])[0])
        full = re.findall(r"receive buffer full: a flood\?\) \[(\d+) so far\]", text)
        assert read + (int(full[-1]) if full else 0) == 200, (garbage, full)  # counted, read or not
    finally:
        heard.extend(drain(tap))
        tap.close()
    usv_acks = [m for m in heard if m.type == ModemTransmission.ACK and m.src == 2]
    assert usv_acks and all(len(m.acked_frame) == 1 for m in usv_acks), [list(m.acked_frame)[:5] for m in usv_acks]


def test_rate_limited_log_reports_every_event() -> None:
    now = [0.0]
    records: list[str] = []

    class Collect(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            records.append(record.getMessage())

    logger = logging.getLogger("tests.ratelimit")
    handler = Collect()
    logger.addHandler(handler)
    try:
        limited = RateLimitedLog(logger, period_s=10, max_keys=2, clock=lambda: now[0])
        for i in range(5):
            limited.error("bad", "bad datagram %d", i)
        limited.flush()
        assert records == ["bad datagram 0"]
        now[0] = 10.0
        limited.flush()
        assert records[-1] == ("bad datagram 4 (the latest of 4 like this since the last such line, "
                               "not logged one by one)")
        assert limited.error("bad", "bad datagram %d", 5) is False  # within the period after the summary
        now[0] = 25.0
        assert limited.error("bad", "bad datagram %d", 6) is True
        assert records[-1] == "bad datagram 6 (1 more like this since the last such line, not logged one by one)"
        for key in ("a", "b", "c", "d"):  # past max_keys (2), new kinds share one key
            limited.warning(key, "kind %s", key)
        assert records[-2:] == ["kind a", "kind b"], records
        limited.flush(final=True)
        assert records[-1] == "kind d (the latest of 2 like this since the last such line, not logged one by one)"
        assert limited.events == 11 and limited.held_back == 7
    finally:
        logger.removeHandler(handler)


# -- 1b. a link thread that fails is reported and restarted --------------------------------------------------


def test_failed_link_thread_is_reported_and_restarted(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING)
    ether = Ether("sat")
    made: list[EtherDriver] = []

    class FailsOnce(EtherDriver):
        """The first driver raises when it reads a datagram (a bug anywhere in the link looks like this)."""

        def do_work(self) -> None:
            super().do_work()
            if self is made[0]:
                raise RuntimeError("injected fault")

    def factory(_cfg: object) -> EtherDriver:
        made.append(FailsOnce(ether))
        return made[-1]

    cfg = PortalConfig()
    link = cfg.link.add(modem_id=2, subnet_mask=0xFF00)
    link.driver.driver_name = "ether:sat"
    link.mac.type = MAC_FIXED_DECENTRALIZED
    for src in (1, 2):
        link.mac.slot.add(src=src, slot_seconds=5, max_frame_bytes=64)
    listener = ether.attach(-1)
    with broker_process(tmp_path, platform="restart") as broker:
        context = ProcessContext(broker.interprocess_config(), application="test/intervehicle", clock=SystemClock())
        portal = IntervehiclePortal(cfg, context, driver_factory=factory)
        try:
            portal.start()
            # the first datagram the first driver reads makes it raise
            ether.send(ModemTransmission(src=1, dest=2, type=ModemTransmission.DATA).SerializeToString())
            wait_until(lambda: portal.running[0].restarts == 1 and portal.running[0].up, 10,
                       "the failed link to be restarted")
            errors = [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR]
            assert any(m.startswith("intervehicle link 2 failed (RuntimeError: injected fault); restarting it")
                       for m in errors), errors
            assert len(made) == 2
            # The restarted link hears its peer again: data from the topside is acked.
            data = ModemTransmission(src=1, dest=2, type=ModemTransmission.DATA, ack_requested=True, frame_start=7)
            data.frame.append(b"")
            ether.send(data.SerializeToString())

            def acked() -> bool:
                heard = [ModemTransmission.FromString(d) for d in list(listener)]
                return any(m.type == ModemTransmission.ACK and list(m.acked_frame) == [7] for m in heard)

            wait_until(acked, 10, "the restarted link to ack")
        finally:
            portal.stop()
            context.close()
            ether.detach(-1)
    assert not any(t.name.startswith("intervehicle") for t in threading.enumerate())


# -- 2. forged frames from another host ----------------------------------------------------------------------

NET = "10.231.77"  # A: .1, B (the attacker): .2; the configured peer .3 does not exist


def ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, timeout=20)


@pytest.fixture
def namespaces() -> Iterator[tuple[str, str]]:
    """Two network namespaces joined by a veth pair (A 10.231.77.1, B .2), loopback up in both."""
    tag = f"{os.getpid() % 100000}"
    ns_a, ns_b, veth_a, veth_b = f"ivh_a{tag}", f"ivh_b{tag}", f"ivha{tag}", f"ivhb{tag}"
    try:
        ip("netns", "add", ns_a)
    except (OSError, subprocess.CalledProcessError) as exc:
        pytest.skip(f"cannot create a network namespace (root and iproute2 needed): {exc}")
    try:
        ip("netns", "add", ns_b)
        ip("link", "add", veth_a, "type", "veth", "peer", "name", veth_b)
        ip("link", "set", veth_a, "netns", ns_a)
        ip("link", "set", veth_b, "netns", ns_b)
        for ns, dev, host in ((ns_a, veth_a, 1), (ns_b, veth_b, 2)):
            ip("-n", ns, "addr", "add", f"{NET}.{host}/24", "dev", dev)
            ip("-n", ns, "link", "set", dev, "up")
            ip("-n", ns, "link", "set", "lo", "up")
    except (OSError, subprocess.CalledProcessError) as exc:
        for ns in (ns_a, ns_b):
            subprocess.run(["ip", "netns", "del", ns], capture_output=True, timeout=20)
        pytest.skip(f"cannot set up a veth pair between namespaces: {exc}")
    try:
        yield ns_a, ns_b
    finally:
        for ns in (ns_a, ns_b):
            subprocess.run(["ip", "netns", "del", ns], capture_output=True, timeout=20)


SEND = ("import socket, sys\n"
        "src, dest, port, data = sys.argv[1], sys.argv[2], int(sys.argv[3]), bytes.fromhex(sys.argv[4])\n"
        "s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)\n"
        "s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(src))\n"
        "s.bind((src, 0))\n"
        "for _ in range(3): s.sendto(data, (dest, port))\n")


def send_from(ns: str, source: str, dest: str, port: int, datagram: bytes) -> None:
    """Send ``datagram`` three times from ``source`` in namespace ``ns`` (multicast or unicast ``dest``)."""
    subprocess.run(["ip", "netns", "exec", ns, sys.executable, "-c", SEND, source, dest, str(port), datagram.hex()],
                   check=True, capture_output=True, timeout=30)


def command_frame(src: int, sides: int) -> bytes:
    """A topside DATA transmission to the USV carrying one USVCommand (polygon of ``sides``)."""
    codec = Codec()
    codec.load(USVCommand)
    msg = ModemTransmission(src=src, dest=2, type=ModemTransmission.DATA, ack_requested=False)
    msg.frame.append(codec.encode(USVCommand(time=time.time(), desired_state=USVCommand.POLYGON,
                                             polygon_sides=sides, polygon_radius=200)))
    return msg.SerializeToString()


def test_forged_frames_from_another_host_are_dropped(tmp_path: Path, namespaces: tuple[str, str]) -> None:
    ns_a, ns_b = namespaces
    (g1, p1), (g2, p2) = random_multicast(), random_multicast()
    # Link 2 (satellite, loopback as both missions configure it) and link 514 (on the veth, peer 10.231.77.3 only).
    cfg_text = (
        f"app {{ simulation {{ time {{ use_sim_time: true warp_factor: {WARP} }} }} }}\n"
        f"intervehicle {{\n{link_block(2, g1, p1, SAT)}\n"
        "link { modem_id: 514 subnet_mask: 0xFF00 driver { driver_type: DRIVER_UDP_MULTICAST "
        f"[goby.acomms.udp_multicast.protobuf.config] {{ listen_address: \"{NET}.1\" multicast_address: \"{g2}\" "
        f"multicast_port: {p2} }} [goby_moos_py.acomms.protobuf.udp_peers] {{ peer_address: \"{NET}.3\" }} }} "
        "mac { type: MAC_FIXED_DECENTRALIZED slot { src: 513 slot_seconds: 5 max_frame_bytes: 64 } "
        "slot { src: 514 slot_seconds: 5 max_frame_bytes: 64 } } }\n}\n")
    cfg_path = tmp_path / "gobyd_ns.pb.cfg"
    cfg_path.write_text(cfg_text)
    ipc = InterProcessPortalConfig(platform="ivns", socket_name=str(tmp_path / "goby_ivns"))
    broker = ChildProcess(["ip", "netns", "exec", ns_a, sys.executable, "-m", "gateway.apps.goby_broker",
                           "--interprocess", text_format.MessageToString(ipc, as_one_line=True), str(cfg_path), "-v"],
                          tmp_path / "gobyd_ns.log", name="goby-broker in namespace A")
    with broker:
        broker.wait_ready(re.escape(READY_PREFIX), timeout=30)
        listening = subprocess.run(["ip", "netns", "exec", ns_a, "ss", "-lunp"], capture_output=True, text=True,
                                   timeout=20).stdout
        assert f"{g1}:{p1}" in listening and f"{g2}:{p2}" in listening, listening
        assert not re.search(rf"(0\.0\.0\.0|\*|\[::\]):({p1}|{p2})\b", listening), listening
        usv = IntervehicleClient(ipc, "usv_app")
        try:
            assert usv.wait_subscribed()
            received: list[USVCommand] = []
            command_subscriber(usv, received)
            # From the topside on this host (loopback, peer modem 1): accepted.
            deadline = time.monotonic() + 20
            while not received and time.monotonic() < deadline:
                send_from(ns_a, "127.0.0.1", g1, p1, command_frame(1, 3))
                usv.poll_until(lambda: bool(received), 1.0)
            assert [c.polygon_sides for c in received[:1]] == [3], broker.output()
            # From host B with the topside's modem id: unicast to A's port, multicast to both groups.
            forged = command_frame(1, 6)
            send_from(ns_b, f"{NET}.2", f"{NET}.1", p1, forged)
            send_from(ns_b, f"{NET}.2", g1, p1, forged)
            send_from(ns_b, f"{NET}.2", g2, p2, command_frame(1, 6))
            wait_until(lambda: "not a peer_address" in broker.output(), 10, "link 514 to refuse host B")
            send_from(ns_a, "127.0.0.1", g1, p1, command_frame(1, 4))  # and the link still works
            assert usv.poll_until(lambda: any(c.polygon_sides == 4 for c in received), 10), broker.output()
            usv.poll(0.5)
        finally:
            usv.close()
        text = broker.output()
    assert 6 not in {c.polygon_sides for c in received}, (received, text)
    refused = [line for line in text.splitlines() if "not a peer_address" in line]
    assert len(refused) == 1 and "link 514: dropping a datagram" in refused[0] and f"from {NET}.2:" in refused[0], text


# -- 3. bad settings are named errors ------------------------------------------------------------------------


def test_negative_warp_with_a_link_is_a_named_error(tmp_path: Path) -> None:
    cfg = tmp_path / "gobyd.pb.cfg"
    cfg.write_text("app { simulation { time { use_sim_time: true warp_factor: -3 } } }\n"
                   "intervehicle {\n" + LoopbackLink(SAT).block(2) + "\n}\n")
    ipc = InterProcessPortalConfig(platform="warp", socket_name=str(tmp_path / "goby_warp"))
    result = subprocess.run([sys.executable, "-m", "gateway.apps.goby_broker", "--interprocess",
                             text_format.MessageToString(ipc, as_one_line=True), str(cfg)],
                            capture_output=True, text=True, timeout=60)
    out = result.stdout + result.stderr
    assert result.returncode not in (0, None) and "Traceback" not in out, out
    assert "warp_factor" in out and "-3" in out, out
