"""``goby-opencpn-interface``: every vehicle's NodeStatus as AIS class B sentences for OpenCPN, as Goby3's
``goby_opencpn_interface`` (src/apps/zeromq/opencpn/opencpn.cpp).

It subscribes to ``node_status`` (interprocess) and keeps each vehicle's last ``filter_length`` reports
(:class:`gateway.goby.ais.AISFleet`, MMSIs from ``mmsi_start`` in the order names first appear).  Every
``position_report_interval`` it writes a type 18 position report, and every ``voyage_report_interval`` a type 24
static report (parts A and B), for each vehicle heard since that report's previous round; a vehicle's first status
is reported at once, as Goby does.  Sentences go to every client of a TCP server (``ais_server``, bound to
``bind_address``, loopback by default) or to a PTY (``ais_serial``: ``port`` is a symlink to its device).

Everything runs on the application's one reactor: the node_status callback, the two timers (simulated seconds
under warp) and the sockets.  Writes never block: a client's unsent bytes wait in its buffer, and a client with more
than ``MAX_BACKLOG`` bytes waiting, or whose socket fails, is dropped without affecting the others.  Unlike Goby,
sentences from OpenCPN (WPL/RTE routes) are read and discarded.
"""

from __future__ import annotations

import contextlib
import logging
import os
import socket
import sys
import termios
import tty
from collections.abc import Callable

from frontseat.groups import node_status
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from frontseat.protobuf.opencpn_config_pb2 import OpenCPNInterfaceConfig
from gateway.goby.ais import AISConverter, AISError, AISFleet
from gateway.goby.portal import SingleThreadApplication, StartError, run_application
from gateway.goby.protobuf.io_config_pb2 import PTYConfig, TCPServerConfig
from util.reactor import Reactor
from util.tcp_fanout import FanOutClient, FanOutServer

log = logging.getLogger(__name__)

MAX_BACKLOG = 256 * 1024  # bytes queued for a client that is not reading before it is dropped
RECV_SIZE = 4096


class SentenceServer:
    """A TCP server on ``reactor`` that writes the same bytes to every connected client (Goby's ``all_clients``)."""

    def __init__(self, reactor: Reactor, cfg: TCPServerConfig) -> None:
        family = socket.AF_INET6 if cfg.ipv6 else socket.AF_INET
        address = cfg.bind_address
        if cfg.ipv6 and address == "127.0.0.1":
            address = "::1"
        if not 0 <= cfg.bind_port <= 65535:
            raise StartError(f"ais_server.bind_port {cfg.bind_port} out of range (0 to 65535)")
        listener = socket.socket(family, socket.SOCK_STREAM)
        try:
            if cfg.set_reuseaddr:
                listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            listener.bind((address, cfg.bind_port))
            listener.listen()
        except OSError as exc:
            listener.close()
            raise StartError(f"cannot bind the AIS server to {address}:{cfg.bind_port}: {exc.strerror}") from None
        self.port: int = listener.getsockname()[1]
        self._clients = FanOutServer(reactor, listener, max_backlog=MAX_BACKLOG, recv_size=RECV_SIZE,
                                     on_data=_ignore_input)
        self._clients.start()
        log.info("serving AIS on %s:%d", address, self.port)

    def write(self, payload: bytes) -> None:
        self._clients.broadcast(payload)

    def close(self) -> None:
        self._clients.close()


def _ignore_input(client: FanOutClient, data: bytes) -> None:
    """OpenCPN may send routes and waypoints; Goby reads and drops them too."""
    log.debug("ignoring %d bytes from %s", len(data), client.peer)


class SentencePty:
    """A pseudo-terminal whose slave device is symlinked at ``cfg.port``; sentences are written to its master.

    When nothing reads the device the terminal's buffer fills: then the oldest unsent bytes beyond ``MAX_BACKLOG``
    are discarded (logged), never blocking the reactor."""

    def __init__(self, reactor: Reactor, cfg: PTYConfig) -> None:
        self._reactor = reactor
        self._link = cfg.port
        self._outbuf = bytearray()
        self._master, self._slave = os.openpty()
        try:
            tty.setraw(self._slave)
            attrs = termios.tcgetattr(self._slave)
            speed = getattr(termios, f"B{cfg.baud}", None)
            if speed is None:
                raise StartError(f"ais_serial.baud {cfg.baud} is not a terminal speed")
            attrs[4] = attrs[5] = speed
            termios.tcsetattr(self._slave, termios.TCSANOW, attrs)
            os.set_blocking(self._master, False)
            if os.path.islink(self._link):
                os.unlink(self._link)
            os.symlink(os.ttyname(self._slave), self._link)
        except OSError as exc:
            self._close_fds()
            raise StartError(f"cannot create the AIS pty at {self._link}: {exc.strerror}") from None
        except StartError:
            self._close_fds()
            raise
        reactor.add_reader(self._master, self._discard_input)
        log.info("writing AIS to %s (%s)", self._link, os.ttyname(self._slave))

    def write(self, payload: bytes) -> None:
        self._outbuf += payload
        if len(self._outbuf) > MAX_BACKLOG:
            excess = len(self._outbuf) - MAX_BACKLOG
            log.warning("nothing is reading %s: discarding %d old bytes", self._link, excess)
            del self._outbuf[:excess]
        self._flush()

    def _flush(self) -> None:
        try:
            sent = os.write(self._master, self._outbuf)
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError as exc:
            log.warning("write to %s failed: %s", self._link, exc)
            sent = len(self._outbuf)
        del self._outbuf[:sent]
        if self._outbuf:
            self._reactor.add_writer(self._master, self._flush)
        else:
            self._reactor.remove_writer(self._master)

    def _discard_input(self) -> None:
        with contextlib.suppress(OSError):
            os.read(self._master, RECV_SIZE)

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self._reactor.remove_reader(self._master)
            self._reactor.remove_writer(self._master)
        with contextlib.suppress(OSError):
            if os.path.islink(self._link):
                os.unlink(self._link)
        self._close_fds()

    def _close_fds(self) -> None:
        for fd in (self._master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)


class OpenCPNInterface(SingleThreadApplication):
    """NodeStatus in, AIS sentences out to the TCP clients or the PTY."""

    def __init__(self, cfg: OpenCPNInterfaceConfig) -> None:
        for name in ("position_report_interval", "voyage_report_interval"):
            value = getattr(cfg, name)
            if not 0 < value < float("inf"):
                raise StartError(f"{name} must be a positive number of seconds, not {value}")
        try:
            self._fleet = AISFleet(cfg.mmsi_start, cfg.filter_length)
        except AISError as exc:
            raise StartError(f"bad configuration: {exc}") from None
        super().__init__(cfg)
        self._heard_pos: set[str] = set()
        self._heard_voy: set[str] = set()
        self._output: SentenceServer | SentencePty | None = None
        if cfg.HasField("ais_server"):
            self._output = SentenceServer(self.reactor, cfg.ais_server)
        elif cfg.HasField("ais_serial"):
            self._output = SentencePty(self.reactor, cfg.ais_serial)
        else:
            log.warning("neither ais_server nor ais_serial is configured: sentences are only logged")
        self.interprocess().subscribe(node_status, NodeStatus, self._on_status)

    @property
    def output(self) -> SentenceServer | SentencePty | None:
        return self._output

    def _warped(self, seconds: float) -> float:
        return seconds / self.context.clock.effective_warp

    def initialize(self) -> None:
        cfg = self.cfg()
        self.reactor.call_every(lambda: self._warped(cfg.position_report_interval), self._position_round,
                                align=False)
        self.reactor.call_every(lambda: self._warped(cfg.voyage_report_interval), self._voyage_round, align=False)

    def finalize(self) -> None:
        if self._output is not None:
            self._output.close()
            self._output = None

    def _on_status(self, status: NodeStatus) -> None:
        """Runs on the application's thread (interprocess callback)."""
        if not status.name:
            log.warning("ignoring a NodeStatus without a name")
            return
        first = status.name not in self._fleet.vehicles
        converter = self._fleet.add_status(status)
        if converter is None:
            return
        if first:  # Goby reports a vehicle's first status at once
            self._send(self._fleet.position_sentences(converter) + self._fleet.static_sentences(converter))
        else:
            self._heard_pos.add(status.name)
            self._heard_voy.add(status.name)

    def _round(self, heard: set[str], build: Callable[[AISConverter], list[str]]) -> None:
        sentences: list[str] = []
        for name in sorted(heard):
            sentences += build(self._fleet.vehicles[name])
        heard.clear()
        self._send(sentences)

    def _position_round(self) -> None:
        self._round(self._heard_pos, self._fleet.position_sentences)

    def _voyage_round(self) -> None:
        self._round(self._heard_voy, self._fleet.static_sentences)

    def _send(self, sentences: list[str]) -> None:
        if not sentences:
            return
        for sentence in sentences:
            log.debug("%s", sentence)
        if self._output is not None:
            self._output.write("".join(s + "\r\n" for s in sentences).encode("ascii"))


def main(argv: list[str] | None = None) -> int:
    return run_application(OpenCPNInterface, OpenCPNInterfaceConfig, argv, prog="goby-opencpn-interface")


if __name__ == "__main__":
    sys.exit(main())
