"""Hosts for a run: Linux network namespaces on a private bridge, one per platform (issue 25, docs/hosts.md).

``HostNetwork(["topside", "usv", "auv0"])`` is a context manager. Entering it makes, for this run only:

* a bridge ``<prefix><run>br`` in the calling namespace with the *console* address ``10.77.X.1/24`` (X picked free
  among the addresses this machine has, so runs side by side do not share a subnet), IGMP snooping off so multicast
  floods to every port;
* per host a namespace ``<prefix><run>-<name>`` holding one end of a veth pair (``eth0``, address ``10.77.X.<2+i>``,
  up, a ``224.0.0.0/4`` route on it so multicast leaves by it, loopback up); the other end is a port of the bridge.

Nothing listens on the console address: the demo only connects from it (recorders, pages) and joins the links'
multicast groups there to count datagrams. ``host.command(argv)`` runs a program inside a host (``ip netns exec``),
``host.shell_prefix`` is the same for a launch line. Leaving the context deletes the namespaces (which deletes their
veth ends, and with them the bridge's), the bridge, and anything of this run left over, even after a failure;
``remove_leftovers(prefix)`` clears what a killed run left (``python -m launch.hosts --clean``).

Needs root and iproute2; :func:`unavailable` says why not (tests skip with that reason).
"""

from __future__ import annotations

import argparse
import ipaddress
import logging
import os
import re
import secrets
import shlex
import shutil
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from types import TracebackType

from launch.errors import LaunchError

log = logging.getLogger(__name__)

DEFAULT_PREFIX = "gmh"  # goby-moos hosts: every namespace and link this module makes starts with it
NETWORK_BASE = "10.77"  # /16 the runs' /24 subnets are taken from
IP_TIMEOUT_S = 20.0
MAX_LINK_NAME = 15  # IFNAMSIZ - 1
_NAME = re.compile(r"^[a-z][a-z0-9_]{0,15}$")
MULTICAST_ROUTE = "224.0.0.0/4"


class HostsError(LaunchError):
    """Hosts cannot be made here (not root, no ``ip``, no namespaces) or an ``ip`` command failed."""


def unavailable() -> str | None:
    """Why hosts cannot be made on this machine, or None when they can (root and iproute2 with ``ip netns``)."""
    if os.geteuid() != 0:
        return "network namespaces need root (run as root, or skip --hosts)"
    if shutil.which("ip") is None:
        return "the ip command (iproute2) is not installed"
    try:
        result = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True, timeout=IP_TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"ip netns list failed: {exc}"
    if result.returncode != 0:
        return f"ip netns is unavailable: {result.stderr.strip() or result.returncode}"
    return None


def ip(*args: str, check: bool = True) -> str:
    """Run ``ip ARGS``; HostsError with its message when it fails (and ``check``)."""
    try:
        result = subprocess.run(["ip", *args], capture_output=True, text=True, timeout=IP_TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise HostsError(f"ip {' '.join(args)}: {exc}") from None
    if check and result.returncode != 0:
        raise HostsError(f"ip {' '.join(args)}: {result.stderr.strip() or f'exit status {result.returncode}'}")
    return result.stdout


@dataclass(frozen=True)
class Host:
    """One host of a run: its name (the platform's), network namespace and address."""

    name: str
    netns: str
    address: str

    def command(self, argv: Sequence[str]) -> list[str]:
        """``argv`` run inside this host."""
        return ["ip", "netns", "exec", self.netns, *argv]

    @property
    def shell_prefix(self) -> str:
        """What goes before a shell command line to run it inside this host."""
        return f"ip netns exec {shlex.quote(self.netns)} "


def _used_subnets() -> set[int]:
    """Third octets of the 10.77.X.0/24 subnets this namespace has an address in."""
    used = set()
    for match in re.finditer(rf"inet {re.escape(NETWORK_BASE)}\.(\d+)\.", ip("-4", "-o", "addr", "show")):
        used.add(int(match[1]))
    return used


@dataclass
class HostNetwork:
    """The hosts of one run (see the module's text). ``hosts[name]`` once entered; ``console`` is the bridge's
    address in the calling namespace."""

    names: Sequence[str]
    prefix: str = DEFAULT_PREFIX
    run_id: str = field(default_factory=lambda: secrets.token_hex(2))
    hosts: dict[str, Host] = field(default_factory=dict)
    console: str = ""
    subnet: ipaddress.IPv4Network | None = None

    def __post_init__(self) -> None:
        if not self.names or len(set(self.names)) != len(self.names):
            raise HostsError(f"hosts need distinct names, not {list(self.names)}")
        if len(self.names) > 250:
            raise HostsError(f"at most 250 hosts on one bridge, not {len(self.names)}")
        for name in self.names:
            if not _NAME.match(name):
                raise HostsError(f"host name {name!r} must be lower-case letters, digits and _ (at most 16)")
        if not re.match(r"^[a-z]{1,4}$", self.prefix):
            raise HostsError(f"prefix {self.prefix!r} must be 1-4 lower-case letters")
        self.tag = f"{self.prefix}{self.run_id}"
        self.bridge = f"{self.tag}br"

    def veth(self, index: int) -> str:
        return f"{self.tag}v{index}"

    def netns(self, name: str) -> str:
        return f"{self.tag}-{name}"

    def __enter__(self) -> HostNetwork:
        reason = unavailable()
        if reason is not None:
            raise HostsError(reason)
        try:
            self._make()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.close()

    def _make(self) -> None:
        free = sorted(set(range(1, 255)) - _used_subnets())
        if not free:
            raise HostsError(f"no free subnet in {NETWORK_BASE}.0.0/16")
        third = free[secrets.randbelow(len(free))]
        self.subnet = ipaddress.IPv4Network(f"{NETWORK_BASE}.{third}.0/24")
        self.console = f"{NETWORK_BASE}.{third}.1"
        ip("link", "add", self.bridge, "type", "bridge", "mcast_snooping", "0")
        ip("addr", "add", f"{self.console}/24", "dev", self.bridge)
        ip("link", "set", self.bridge, "up")
        for index, name in enumerate(self.names):
            host = Host(name, self.netns(name), f"{NETWORK_BASE}.{third}.{2 + index}")
            outside = self.veth(index)
            ip("netns", "add", host.netns)
            self.hosts[name] = host
            ip("link", "add", outside, "type", "veth", "peer", "name", f"{outside}p", "netns", host.netns)
            ip("link", "set", outside, "master", self.bridge, "up")
            ip("-n", host.netns, "link", "set", f"{outside}p", "name", "eth0")
            ip("-n", host.netns, "addr", "add", f"{host.address}/24", "dev", "eth0")
            ip("-n", host.netns, "link", "set", "eth0", "multicast", "on", "up")
            ip("-n", host.netns, "link", "set", "lo", "up")
            ip("-n", host.netns, "route", "add", MULTICAST_ROUTE, "dev", "eth0")
        log.info("hosts %s on %s (console %s)", ", ".join(f"{h.name} {h.address}" for h in self.hosts.values()),
                 self.bridge, self.console)

    def close(self) -> list[str]:
        """Delete everything of this run (what is already gone is skipped); returns what was removed."""
        return remove_leftovers(self.tag)

    def __getitem__(self, name: str) -> Host:
        return self.hosts[name]


def _names(kind: str) -> list[str]:
    if kind == "netns":
        return [line.split()[0] for line in ip("netns", "list").splitlines() if line.strip()]
    return [line.split()[1].rstrip(":").split("@")[0] for line in ip("-o", "link", "show").splitlines()]


def remove_leftovers(prefix: str = DEFAULT_PREFIX) -> list[str]:
    """Delete every namespace and link whose name starts with ``prefix`` (a run's tag, or the default prefix for
    every run's); returns their names. Processes still in a namespace keep it alive until they exit, unreachable."""
    removed = []
    for netns in _names("netns"):
        if netns.startswith(prefix):
            ip("netns", "del", netns, check=False)
            removed.append(netns)
    for link in _names("link"):
        if link.startswith(prefix):
            ip("link", "del", link, check=False)
            removed.append(link)
    return removed


def processes_in(netns: str) -> list[int]:
    """Pids of the processes in a namespace (``ip netns pids``)."""
    return [int(p) for p in ip("netns", "pids", netns, check=False).split()]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m launch.hosts", description=__doc__.split("\n\n")[0])
    parser.add_argument("--clean", action="store_true",
                        help="remove the namespaces and links left over by killed runs (names starting with --prefix)")
    parser.add_argument("--prefix", default=DEFAULT_PREFIX, help=f"name prefix (default {DEFAULT_PREFIX})")
    args = parser.parse_args(argv)
    reason = unavailable()
    if reason is not None:
        print(f"hosts: {reason}", file=sys.stderr)
        return 1
    if not args.clean:
        found = [n for kind in ("netns", "link") for n in _names(kind) if n.startswith(args.prefix)]
        print("\n".join(found) if found else f"no namespaces or links named {args.prefix}*")
        return 0
    try:
        removed = remove_leftovers(args.prefix)
    except HostsError as exc:
        print(f"hosts: {exc}", file=sys.stderr)
        return 1
    print(f"removed {', '.join(removed)}" if removed else f"nothing named {args.prefix}* to remove")
    return 0


if __name__ == "__main__":
    sys.exit(main())
