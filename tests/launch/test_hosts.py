"""The trail mission across hosts (issue 25): each platform in its own network namespace on a private bridge.

``launch.hosts`` makes and removes the hosts (nothing of a run is left, even after a failure); ``python -m
launch.trail.demo --hosts`` runs topside, USV and AUVs on four hosts with 20% acoustic loss and still accounts for
every command and trails; ``--split-usv`` runs the USV on two hosts joined by Goby's interprocess TCP transport and
NAV / DESIRED_* still flow between them. While the missions run, every listening TCP socket inside each host is on
that host's address or loopback (never 0.0.0.0), read from the namespace's /proc/net/tcp. Root only: skipped with the
reason where network namespaces cannot be made.
"""

from __future__ import annotations

import ipaddress
import re
import shutil
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from google.protobuf import text_format

import launch.liaison.protobuf.liaison_web_pb2  # noqa: F401 - registers the extensions the configs use
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from gateway.moos import comms
from launch.hosts import HostNetwork, HostsError, ip, remove_leftovers, unavailable
from launch.launchfile import parse_file
from launch.process_group import child_environment
from launch.trail.config import generate
from launch.trail.settings import TRAIL_DIR, TrailSettings, Vehicle

NEEDED = ("auv-manager", "topside-manager", "usv-manager", "goby-launch")
REASON = unavailable()
needs_hosts = pytest.mark.skipif(REASON is not None, reason=f"no hosts here: {REASON}")
needs_mission = pytest.mark.skipif(any(shutil.which(p, path=child_environment()["PATH"]) is None for p in NEEDED),
                                   reason=f"the mission's programs ({', '.join(NEEDED)}) are not installed")
HOSTS_LINE = re.compile(r"^hosts: (.*); console (\S+) on bridge (\S+)", re.M)
HOST = re.compile(r"(\w+) (\d+\.\d+\.\d+\.\d+) \((\S+)\)")
ACCOUNT = re.compile(r"^  (satellite|acomms) \((.*)\): (\d+) sent x (\d+) recipients? = (\d+): (\d+) acked, "
                     r"(\d+) expired(.*)$", re.M)
TRAIL = re.compile(r"^  (AUV_\d+) \(angle [\d.]+, depth [\d.]+ m\): trailing from t=\d+ s; range error mean "
                   r"([\d.]+), max ([\d.]+)", re.M)
LISTEN, ESTABLISHED = "0A", "01"
RUN_TIMEOUT_S = 150


def leftovers(tag: str) -> list[str]:
    names = [line.split()[0] for line in ip("netns", "list").splitlines() if line.strip()]
    names += [line.split()[1].rstrip(":").split("@")[0] for line in ip("-o", "link", "show").splitlines()]
    return [n for n in names if n.startswith(tag)]


def _address(hex_text: str) -> str:
    """An address of /proc/net/tcp{,6} (32-bit words in host order); IPv4-mapped IPv6 (ZeroMQ's IPv6 option makes
    those) as its IPv4 address."""
    raw = b"".join(bytes.fromhex(hex_text[i:i + 8])[::-1] for i in range(0, len(hex_text), 8))
    if len(raw) == 4:
        return socket.inet_ntoa(raw)
    address = ipaddress.IPv6Address(raw)
    return str(address.ipv4_mapped or address)


def tcp_sockets(netns: str) -> list[tuple[str, int, str, int, str]]:
    """(local address, port, remote address, port, state) of every TCP socket in a namespace, IPv4 and IPv6."""
    out = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        text = subprocess.run(["ip", "netns", "exec", netns, "cat", table], capture_output=True, text=True,
                              check=True, timeout=20).stdout
        for line in text.splitlines()[1:]:
            fields = line.split()
            (local, lport), (remote, rport) = (f.split(":") for f in fields[1:3])
            out.append((_address(local), int(lport, 16), _address(remote), int(rport, 16), fields[3]))
    return out


# -- the hosts themselves ------------------------------------------------------------------------------------


@needs_hosts
def test_hosts_reach_each_other_share_multicast_and_are_removed() -> None:
    code = ("import socket, struct, sys\n"
            "a, port = sys.argv[1], int(sys.argv[2])\n"
            "s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)\n"
            "s.bind(('239.142.7.7', port)); s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, "
            "struct.pack('4s4s', socket.inet_aton('239.142.7.7'), socket.inet_aton(a)))\n"
            "srv = socket.create_server((a, port)); print('ready', flush=True)\n"
            "c, peer = srv.accept(); print('tcp', c.recv(10).decode(), peer[0], flush=True)\n"
            "s.settimeout(10); data, peer = s.recvfrom(100); print('udp', data.decode(), peer[0], flush=True)\n")
    send = ("import socket, sys\n"
            "a, b, port = sys.argv[1], sys.argv[2], int(sys.argv[3])\n"
            "socket.create_connection((b, port), timeout=5).sendall(b'hello')\n"
            "u = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)\n"
            "u.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(a))\n"
            "u.sendto(b'group', ('239.142.7.7', port))\n")
    with HostNetwork(["alpha", "beta"]) as network:
        tag = network.tag
        alpha, beta = network["alpha"], network["beta"]
        assert network.subnet is not None and ipaddress.ip_address(alpha.address) in network.subnet and alpha.address != beta.address
        assert len(leftovers(tag)) == 2 + 1 + 2  # two namespaces, the bridge, two veth ends outside
        listener = subprocess.Popen(beta.command([sys.executable, "-c", code, beta.address, "45999"]),
                                    stdout=subprocess.PIPE, text=True)
        try:
            assert listener.stdout is not None and listener.stdout.readline().strip() == "ready"
            subprocess.run(alpha.command([sys.executable, "-c", send, alpha.address, beta.address, "45999"]),
                           check=True, timeout=20)
            out, _ = listener.communicate(timeout=20)
        finally:
            if listener.poll() is None:
                listener.kill()
                listener.communicate()
        # TCP between hosts, and multicast sent on alpha's address crossed the bridge to beta's group
        assert out.split("\n")[:2] == [f"tcp hello {alpha.address}", f"udp group {alpha.address}"], out
        # beta's server is reachable only inside the run's network: no host of the machine itself listens
        assert all(local != "0.0.0.0" for local, *_ in tcp_sockets(beta.netns))
    assert leftovers(tag) == []


@needs_hosts
def test_a_failed_start_and_a_killed_run_leave_nothing() -> None:
    network = HostNetwork(["one", "two"])
    with pytest.raises(HostsError, match="distinct"):
        HostNetwork(["one", "one"])
    with pytest.raises(HostsError, match="lower-case"):
        HostNetwork(["Bad Name"])
    # A run that fails half-way (its second namespace exists already) removes what it made.
    ip("netns", "add", network.netns("two"))
    try:
        with pytest.raises(HostsError, match="netns add"), network:
            pass  # pragma: no cover - entering fails
        assert leftovers(network.tag) == []
    finally:
        ip("netns", "del", network.netns("two"), check=False)
    # A killed run's namespaces and links (never closed) go with remove_leftovers(prefix).
    killed = HostNetwork(["one"])
    killed._make()
    assert leftovers(killed.tag)
    removed = remove_leftovers(killed.tag)
    assert killed.netns("one") in removed and killed.bridge in removed
    assert leftovers(killed.tag) == []


def test_split_usv_launch_files_are_usv_launch_and_talk_tcp(tmp_path: Path) -> None:
    whole = [e.command for e in parse_file(TRAIL_DIR / "usv.launch").entries]
    front = [e.command for e in parse_file(TRAIL_DIR / "usv_frontseat.launch").entries]
    back = [e.command for e in parse_file(TRAIL_DIR / "usv_backseat.launch").entries]
    assert sorted(front + back) == sorted(whole)
    assert all(c.split()[0] in ("frontseat-sim", "frontseat-interface") for c in front)
    settings = TrailSettings(run_dir=tmp_path, broker_address="10.9.8.7", broker_port=12345, moos_address="10.9.8.7",
                             link_address="10.9.8.6", link_peers="10.9.8.0/24")
    usv = Vehicle("usv", 1)
    cfg = text_format.Parse(generate("usv", "gobyd", settings, usv), GobyDaemonConfig())
    assert cfg.interprocess.transport == InterProcessPortalConfig.TCP
    assert (cfg.interprocess.ipv4_address, cfg.interprocess.tcp_port) == ("10.9.8.7", 12345)
    link = generate("usv", "gobyd", settings, usv)
    assert 'listen_address: "10.9.8.6"' in link and 'peer_address: "10.9.8.0/24"' in link
    assert 'server: "10.9.8.7"' in generate("usv", "frontseat_interface", settings, usv)
    assert generate("usv", "moosdb_flags", settings, usv) == "--moos_address=10.9.8.7"
    assert generate("usv", "moosdb_flags", settings.replace(moosdb="MOOSDB"), usv) == ""


# -- the mission across hosts --------------------------------------------------------------------------------


class DemoRun:
    """``python -m launch.trail.demo --hosts ...`` as a child; ``lines`` as they come; ``probe`` runs once every
    vehicle is under helm command (the mission is then up on every host)."""

    def __init__(self, args: list[str], out: Path) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "launch.trail.demo", "--hosts", "--moosdb", "ours", "--helm", "ours",
             "--warp", "20", "--out", str(out), *args],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines: list[str] = []
        self._timer = threading.Timer(RUN_TIMEOUT_S, self.proc.kill)
        self._timer.start()

    def __iter__(self) -> Iterator[str]:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line)
            yield line

    @property
    def text(self) -> str:
        return "".join(self.lines)

    def finish(self) -> str:
        for _ in self:
            pass
        self.proc.wait()
        self._timer.cancel()
        return self.text

    def hosts(self) -> dict[str, tuple[str, str]]:
        """name -> (address, namespace), from the demo's hosts line."""
        match = HOSTS_LINE.search(self.text)
        assert match, self.text
        return {name: (address, netns) for name, address, netns in HOST.findall(match[1])}


def listeners_outside_host(hosts: dict[str, tuple[str, str]]) -> dict[str, list[tuple[str, int]]]:
    """Per host, its listening TCP sockets on neither its own address nor loopback (the run's only bad binds)."""
    bad: dict[str, list[tuple[str, int]]] = {}
    for name, (address, netns) in hosts.items():
        listening = [(local, port) for local, port, _, _, state in tcp_sockets(netns) if state == LISTEN]
        assert listening, f"nothing listens on {name}"  # the probe reached a live host
        wrong = [(a, p) for a, p in listening if a != address and not ipaddress.ip_address(a).is_loopback]
        if wrong:
            bad[name] = wrong
    return bad


def moos_mail(address: str, port: int, names: tuple[str, ...], seconds: float = 6.0) -> dict[str, str]:
    """Variable -> its poster, for each of ``names`` mailed to a client of the MOOSDB at ``address:port``."""
    client = comms()
    client.set_on_connect_callback(lambda: all(client.register(n, 0) for n in names))
    client.run(address, port, "uHostsTest")
    seen: dict[str, str] = {}
    deadline = time.monotonic() + seconds
    try:
        while time.monotonic() < deadline and len(seen) < len(names):
            for msg in client.fetch():
                seen.setdefault(msg.key(), msg.source())
            time.sleep(0.1)
    finally:
        client.close(True)
    return seen


@needs_hosts
@needs_mission
def test_four_hosts_with_lossy_acoustics_account_for_every_command_and_trail(tmp_path: Path) -> None:
    # 400 sim s after RECOVER: at 20% loss an acoustic ack may need a few slot cycles (retried within the ttl);
    # 200 s left one unsettled at the end on a loaded machine
    run = DemoRun(["--auvs", "2", "--duration", "700", "--schedule", "0:polygon:6:200,20:waypoints,300:recover",
                   "--acomms-loss", "0.2", "--channel-seed", "3"], tmp_path)
    bad: dict[str, list[tuple[str, int]]] | None = None
    hosts: dict[str, tuple[str, str]] = {}
    for line in run:
        if line.startswith("every vehicle under helm command"):
            hosts = run.hosts()
            bad = listeners_outside_host(hosts)
    out = run.finish()
    assert run.proc.returncode == 0, out
    assert set(hosts) == {"topside", "usv", "auv0", "auv1"}, out
    assert bad == {}, f"listening outside the host's address or loopback: {bad}"
    assert len({address for address, _ in hosts.values()}) == 4
    assert "channels: satellite lossless; acomms loss 20%, seed 3" in out
    accounts = {m[0]: m for m in ACCOUNT.findall(out)}
    assert set(accounts) == {"satellite", "acomms"}, out
    for link, (_, _, sent, recipients, deliveries, acked, expired, tail) in accounts.items():
        assert (int(sent), int(recipients)) == ((2, 1) if link == "satellite" else (1, 2)), out
        assert int(deliveries) == int(acked) + int(expired), out  # nothing silent
        assert "UNSETTLED" not in tail, out
    trails = {name: float(mean) for name, mean, _ in TRAIL.findall(out)}
    assert set(trails) == {"AUV_0", "AUV_1"}, out  # both came within 20 m of their trail point
    # the trail range is 50 m; a lossless run keeps the mean range error near 10 m (docs/hosts.md), a lossy one on a
    # loaded 2-core machine has reached 42 m (a fix lost at a turn keeps an AUV off for a while): an AUV that does
    # not trail is hundreds of metres off, which this bound (twice the trail range) catches
    assert all(error < 100 for error in trails.values()), "\n".join(line for line in out.splitlines()
                                                                     if "AUV_" in line)
    assert "RECOVER never reached" not in out, out
    netns_tag = next(iter(hosts.values()))[1].split("-")[0]
    assert leftovers(netns_tag) == []


@needs_hosts
@needs_mission
def test_usv_on_two_hosts_over_tcp_still_drives(tmp_path: Path) -> None:
    run = DemoRun(["--split-usv", "--auvs", "1", "--duration", "150", "--schedule", "0:polygon:6:200,20:waypoints"],
                  tmp_path)
    hosts: dict[str, tuple[str, str]] = {}
    bad: dict[str, list[tuple[str, int]]] | None = None
    mail: dict[str, str] = {}
    front: list[tuple[str, int, str, int, str]] = []
    back: list[tuple[str, int]] = []
    for line in run:
        if line.startswith("every vehicle under helm command"):
            hosts = run.hosts()
            bad = listeners_outside_host(hosts)
            front = tcp_sockets(hosts["usv_frontseat"][1])
            back = [(a, p) for a, p, _, _, state in tcp_sockets(hosts["usv"][1]) if state == LISTEN]
            mail = moos_mail(hosts["usv"][0], 9001, ("NAV_X", "DESIRED_HEADING", "DESIRED_SPEED"))
    out = run.finish()
    assert run.proc.returncode == 0, out
    assert set(hosts) == {"topside", "usv", "usv_frontseat", "auv0"}, out
    assert bad == {}, f"listening outside the host's address or loopback: {bad}"
    usv, usv_front = hosts["usv"][0], hosts["usv_frontseat"][0]
    # The backseat's broker listens on its own address, TCP port 11144 (Goby's interprocess TCP transport).
    assert (usv, 11144) in back, back
    # The frontseat host's interface talks to the backseat's broker (its publish/subscribe ports, which the manager
    # on 11144 announced; the manager's own connection is short-lived) and MOOSDB across the bridge.
    remote = {(r, rp) for local, _, r, rp, state in front if state == ESTABLISHED and local == usv_front}
    assert (usv, 9001) in remote, front
    broker_ports = {(a, p) for a, p in back if p not in (9001, 11144) and a == usv}
    assert len(remote & broker_ports) >= 2, (front, back)
    # NAV comes from the frontseat computer's interface, DESIRED_* from the backseat's helm, both through MOOS.
    assert set(mail) == {"NAV_X", "DESIRED_HEADING", "DESIRED_SPEED"}, mail
    assert re.search(r"usv: interface [^;]*COMMAND", out) and "WAYPOINTS" in out, out  # its timeline ends in COMMAND
    distance = re.search(r"^  usv: .*; (\d+) m over (\d+) fixes", out, re.M)
    assert distance and int(distance[1]) > 100, out
    assert (tmp_path / "run" / "logs" / "launch" / "usv_frontseat" / "usv_frontseat.frontseat-interface.log").is_file()
    assert leftovers(hosts["usv"][1].split("-")[0]) == []
