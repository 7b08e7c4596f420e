"""goby-opencpn-interface as a real process on a real broker: NodeStatus published with PortalClient, AIS read by
TCP clients and decoded by pyais (an independent decoder); and the AIS codec's range checks, decoded by pyais."""

from __future__ import annotations

import math
import socket
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pyais
import pytest

from frontseat.groups import node_status
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.ais import (
    AISFleet,
    PositionReport,
    StaticReport,
    encode_position,
    encode_static,
    to_sentences,
)
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process, broker_process
from util.geodesy import UTMGeodesy
from util.process import ChildProcess, free_port, port_open, wait_until

MMSI_START = 988700000
ORIGIN = (42.358, -71.087)
KNOTS_PER_MPS = 3600.0 / 1852.0


@dataclass
class Vehicle:
    name: str
    speed: float  # m/s
    heading: float  # degrees
    x: float = 0.0
    y: float = 0.0
    published: list[tuple[float, float]] = field(default_factory=list)


@dataclass
class AISClient:
    """A TCP client of the interface: complete lines as they arrive, with their arrival times."""

    sock: socket.socket
    buf: bytes = b""
    lines: list[tuple[float, str]] = field(default_factory=list)

    @classmethod
    def connect(cls, port: int) -> AISClient:
        sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        sock.setblocking(False)
        return cls(sock)

    def read(self) -> None:
        while True:
            try:
                data = self.sock.recv(65536)
            except BlockingIOError:
                return
            if not data:
                return
            self.buf += data
            *complete, self.buf = self.buf.split(b"\r\n")
            now = time.monotonic()
            self.lines.extend((now, line.decode("ascii")) for line in complete)

    def decoded(self) -> list[tuple[float, dict]]:
        return [(t, pyais.decode(line).asdict()) for t, line in self.lines]

    def close(self) -> None:
        self.sock.close()


@pytest.fixture
def broker(tmp_path: Path) -> Iterator[BrokerProcess]:
    with broker_process(tmp_path, platform="topside") as running:
        yield running


def start_interface(broker: BrokerProcess, tmp_path: Path, position_s: float, voyage_s: float) -> tuple[ChildProcess, int]:
    port = free_port()
    app = app_process([sys.executable, "-m", "frontseat.apps.goby_opencpn_interface", "-vv",
                       "--ais_server", f"bind_port: {port}", "--mmsi_start", str(MMSI_START),
                       "--filter_length", "3", "--position_report_interval", str(position_s),
                       "--voyage_report_interval", str(voyage_s)], tmp_path / "opencpn.log", env=broker.env())
    try:
        wait_until(lambda: port_open(port) or not app.running, 30, "the AIS server")
        assert app.running, app.stderr_text()
    except BaseException:
        app.stop()
        raise
    return app, port


class Fleet:
    """Vehicles moving in straight lines, published as NodeStatus (simulated time advances 0.1 s per step)."""

    def __init__(self, client: PortalClient, vehicles: list[Vehicle]) -> None:
        self.client = client
        self.vehicles = vehicles
        self.geo = UTMGeodesy(*ORIGIN)
        self.t = 1_700_000_000.0

    def step(self) -> None:
        self.t += 0.1
        for v in self.vehicles:
            v.x += v.speed * 0.1 * math.sin(math.radians(v.heading))
            v.y += v.speed * 0.1 * math.cos(math.radians(v.heading))
            lat, lon = self.geo.to_geo(v.x, v.y)
            status = NodeStatus(time=self.t, name=v.name)
            status.global_fix.lat, status.global_fix.lon = lat, lon
            status.pose.heading = v.heading
            status.speed.over_ground = v.speed
            self.client.publish(node_status, status)
            v.published.append((lat, lon))

    def run(self, seconds: float, clients: list[AISClient]) -> None:
        """Publish every 0.1 s for ``seconds``, reading the clients meanwhile."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.step()
            self.client.poll(0.1)
            for c in clients:
                c.read()


    def run_until(self, predicate: Callable[[], bool], clients: list[AISClient], timeout_s: float = 30.0) -> None:
        """Publish and read until ``predicate()`` holds; fails the test after ``timeout_s``."""
        deadline = time.monotonic() + timeout_s
        while not predicate():
            assert time.monotonic() < deadline, "no AIS arrived"
            self.run(0.3, clients)


def checksum_ok(line: str) -> bool:
    body, _, given = line[1:].partition("*")
    x = 0
    for ch in body.encode():
        x ^= ch
    return line.startswith("!AIVDM,") and given == f"{x:02X}"


def test_sentences_decode_to_the_vehicles(broker: BrokerProcess, tmp_path: Path) -> None:
    app, port = start_interface(broker, tmp_path, position_s=0.5, voyage_s=1.5)
    vehicles = [Vehicle("auv_1", 1.5, 30.0), Vehicle("usv", 2.5, 250.0)]
    first = AISClient.connect(port)
    try:
        with PortalClient(broker.interprocess_config(), name="publisher") as client:
            assert client.wait_ready()
            fleet = Fleet(client, vehicles)
            fleet.run_until(lambda: len({m["mmsi"] for _, m in first.decoded()}) >= 2, [first])
            fleet.run(5.0, [first])
            late = AISClient.connect(port)  # mid-run
            fleet.run(4.0, [first, late])
        assert app.running, app.stderr_text()
    finally:
        first.close()
        assert app.stop() == 0, app.stderr_text()
    late.close()

    assert first.lines and all(checksum_ok(line) for _, line in first.lines), first.lines[:5]
    decoded = first.decoded()
    names = {m["mmsi"]: m["shipname"] for _, m in decoded if m["msg_type"] == 24 and m["partno"] == 0}
    assert names == {MMSI_START: "AUV_1", MMSI_START + 1: "USV"}
    assert {m["ship_type"] for _, m in decoded if m["msg_type"] == 24 and m["partno"] == 1} == {90}
    for vehicle, mmsi in zip(vehicles, (MMSI_START, MMSI_START + 1), strict=True):
        reports = [m for _, m in decoded if m["msg_type"] == 18 and m["mmsi"] == mmsi]
        assert len(reports) >= 5
        for m in reports:
            # within 1e-5 degrees in latitude and in longitude of a published NodeStatus (the bound)
            nearest = min(max(abs(m["lat"] - lat), abs(m["lon"] - lon)) for lat, lon in vehicle.published)
            assert nearest < 1e-5, (vehicle.name, m)
            assert m["speed"] == pytest.approx(vehicle.speed * KNOTS_PER_MPS, abs=0.051)
            assert m["heading"] == round(vehicle.heading)
        for m in reports[1:]:  # the first report has one status: no course yet
            assert abs((m["course"] - vehicle.heading + 180) % 360 - 180) < 0.5, (vehicle.name, m)

    # the client that connected mid-run gets positions every 0.5 s and statics every 1.5 s
    late_decoded = late.decoded()
    assert all(checksum_ok(line) for _, line in late.lines)
    for mmsi in (MMSI_START, MMSI_START + 1):
        times = [t for t, m in late_decoded if m["msg_type"] == 18 and m["mmsi"] == mmsi]
        statics = [m for _, m in late_decoded if m["msg_type"] == 24 and m["mmsi"] == mmsi]
        assert 5 <= len(times) <= 10, times  # 4 s at 0.5 s
        assert 2 <= len(statics) // 2 <= 4, statics  # 4 s at 1.5 s, parts A and B
        gaps = [b - a for a, b in zip(times, times[1:], strict=False)]
        assert sorted(gaps)[len(gaps) // 2] == pytest.approx(0.5, abs=0.2), gaps


def test_a_client_that_leaves_does_not_stop_the_others(broker: BrokerProcess, tmp_path: Path) -> None:
    app, port = start_interface(broker, tmp_path, position_s=0.3, voyage_s=1.0)
    stays = AISClient.connect(port)
    leaves = AISClient.connect(port)
    reset = AISClient.connect(port)
    try:
        with PortalClient(broker.interprocess_config(), name="publisher") as client:
            assert client.wait_ready()
            fleet = Fleet(client, [Vehicle("auv_2", 1.0, 90.0)])
            fleet.run_until(lambda: bool(leaves.lines and reset.lines), [stays, leaves, reset])
            leaves.close()
            reset.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b"\x01\x00\x00\x00\x00\x00\x00\x00")
            reset.close()  # abortive close: RST
            before = len(stays.lines)
            fleet.run(3.0, [stays])
            assert len([1 for _, m in stays.decoded()[before:] if m["msg_type"] == 18]) >= 5
            third = AISClient.connect(port)  # the server still accepts
            fleet.run(1.5, [stays, third])
            third.close()
            assert any(pyais.decode(line).asdict()["mmsi"] == MMSI_START for _, line in third.lines)
        assert app.running, app.stderr_text()
    finally:
        stays.close()
        assert app.stop() == 0, app.stderr_text()
    assert "disconnected" in app.stderr_text() or "failed" in app.stderr_text()


# ------------------------------------------------------------------------------------------ codec range checks
def decode(bits: tuple[int, int]) -> dict:
    return pyais.decode(*to_sentences(bits)).asdict()


def test_unavailable_and_out_of_range_fields() -> None:
    m = decode(encode_position(PositionReport(MMSI_START, lat=math.nan, lon=-71.0, sog=math.inf, cog=math.nan,
                                              heading=None, second=None)))
    assert (m["lat"], m["lon"], m["speed"], m["course"], m["heading"], m["second"]) == (91.0, 181.0, 102.3, 360.0,
                                                                                      511, 60)
    m = decode(encode_position(PositionReport(MMSI_START, lat=95.0, lon=10.0, sog=1000.0, cog=-90.0, heading=720.4)))
    assert (m["lat"], m["lon"], m["speed"], m["course"], m["heading"]) == (91.0, 181.0, 102.2, 270.0, 0)
    m = decode(encode_position(PositionReport(MMSI_START, lat=-33.123456, lon=151.987654, sog=-1.0, cog=359.97)))
    assert m["lat"] == pytest.approx(-33.123456, abs=1e-5) and m["lon"] == pytest.approx(151.987654, abs=1e-5)
    assert (m["speed"], m["course"]) == (102.3, 0.0)
    m = decode(encode_static(StaticReport(MMSI_START, "very long vehicle name ~ é"), 0))
    assert m["shipname"] == "VERY LONG VEHICLE NA"
    with pytest.raises(ValueError, match="MMSI"):
        encode_position(PositionReport(2**30))


def test_mmsi_in_order_first_seen_and_multi_sentence() -> None:
    fleet = AISFleet(MMSI_START, 2)
    for name in ("b", "a", "b", "c"):
        status = NodeStatus(time=1.0, name=name)
        status.global_fix.lat, status.global_fix.lon = 1.0, 2.0
        status.pose.SetInParent()
        status.speed.over_ground = 0.0
        fleet.add_status(status)
    assert {n: c.mmsi for n, c in fleet.vehicles.items()} == {"b": MMSI_START, "a": MMSI_START + 1,
                                                             "c": MMSI_START + 2}
    bits = encode_static(StaticReport(MMSI_START, "X"), 0)
    value, length = bits
    long_bits = ((value << 200) | 0, length + 200)  # 368 bits: two sentences
    sentences = to_sentences(long_bits, fleet.next_sequence_id)
    assert len(sentences) == 2 and all(checksum_ok(s) for s in sentences)
    assert sentences[0].split(",")[1:4] == ["2", "1", "0"]
    assert pyais.decode(*sentences).asdict()["mmsi"] == MMSI_START
