"""``moos-share``: pShare's role: MOOS variables to and from other MOOSDBs over UDP, in pShare's datagrams.

Reads its ``ProcessConfig = pShare`` block (``--alias NAME`` for another); the format, the wire format and the
deliberate differences from pShare are in docs/moos_share.md and :mod:`gateway.moos.share`.

Outputs: every variable named by an ``Output`` is registered with the DB; each notification is renamed and sent,
one datagram per route, as pShare's ``ApplyRoutes``. Inputs: each ``Input`` route is a UDP socket bound to the
route's own address (``localhost:9201`` binds 127.0.0.1:9201; pShare binds every address); each datagram is
checked and posted to the DB keeping its source, as pShare's ``Post(msg, true)``, unless this share is itself
registered for that name (pShare's loop guard). ``<NAME>_CMD`` (``PSHARE_CMD``) adds routes at run time.
``PSHARE_OUTPUT_SUMMARY`` and ``PSHARE_INPUT_SUMMARY`` are posted on connection and every second after.

Threads: one. The MOOS client (``comms(reactor=...)``) and the UDP sockets are readers of one
:class:`util.reactor.Reactor`; nothing polls: a datagram or a notification wakes it.
"""

from __future__ import annotations

import errno
import logging
import socket
import struct
from collections.abc import Callable
from dataclasses import dataclass

from gateway.apps.moos_tool_args import parse_moos_app_args
from gateway.moos import MissionFileError, MoosClock
from gateway.moos.message import MoosMessage, to_bytes
from gateway.moos.mission_file import MissionFile
from gateway.moos.reactor_app import MoosReactorApp, serve
from gateway.moos.share import (
    MAX_DATAGRAM,
    SUMMARY_INPUT,
    SUMMARY_OUTPUT,
    Address,
    Changes,
    InputRoute,
    ShareError,
    ShareSettings,
    ShareTable,
    decode_datagram,
    encode_datagram,
)
from util.ratelimit import RateLimitedLog
from util.reactor import Timer

log = logging.getLogger(__name__)
DEFAULT_APP_NAME = "pShare"
RECV_BURST = 256  # datagrams read per wake-up of one socket before the reactor serves the others
SUMMARY_PERIOD = 1.0


@dataclass
class ShareCounters:
    received: int = 0  # datagrams read
    posted: int = 0  # messages posted to the DB
    malformed: int = 0  # datagrams dropped as malformed
    unwanted: int = 0  # dropped: not on the white list, or a name this share sends (loop guard)
    sent: int = 0  # datagrams sent
    send_failed: int = 0  # datagrams not sent (too big, or the socket refused)
    not_posted: int = 0  # the DB link was down

    def describe(self) -> str:
        return (f"{self.received} datagrams received, {self.posted} posted, {self.malformed} malformed dropped, "
                f"{self.unwanted} unwanted dropped, {self.not_posted} not posted (DB down); {self.sent} sent, "
                f"{self.send_failed} not sent")


def _bind_input(address: Address) -> socket.socket:
    """A non-blocking UDP socket bound to the input route's address (a multicast route joins its group)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 64 * 1024 * 28)
        except OSError:
            log.debug("could not enlarge the receive buffer of %s", address)
        sock.bind(address.sockaddr)
        if address.multicast:
            mreq = struct.pack("4s4s", socket.inet_aton(address.ip), socket.inet_aton("0.0.0.0"))
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
        sock.setblocking(False)
    except OSError:
        sock.close()
        raise
    return sock


class ShareApp(MoosReactorApp):
    """One pShare connected to one MOOSDB; :meth:`run` serves on the calling thread until :meth:`stop`."""

    def __init__(self, mission_path: str, alias: str | None = None) -> None:
        self.mission = MissionFile(mission_path)
        name = alias or DEFAULT_APP_NAME
        block = name if self.mission.has_process_config(name) else DEFAULT_APP_NAME
        pairs = self.mission.process_config(block)
        self.where = f"{self.mission.path}: ProcessConfig = {block}"
        settings = ShareSettings()
        outputs, inputs = [], []
        for key, value in pairs:
            name = key.strip().lower()
            if name == "output":
                outputs.append(value)
            elif name == "input":
                inputs.append(value)
            elif name == "multicast_address":
                settings.multicast_address = value.strip()
            elif name == "multicast_base_port":
                try:
                    port = int(value.strip())
                except ValueError:
                    port = -1
                if not 0 <= port <= 65535:
                    raise MissionFileError(f"{self.where}: multicast_base_port must be an unsigned 16 bit number")
                settings.multicast_base_port = port
        self.table = ShareTable(settings)
        self.counters = ShareCounters()
        self.bad = RateLimitedLog(log, period_s=10.0)
        super().__init__(name, MoosClock(self.mission.time_warp), self.mission.server_host, self.mission.server_port,
                         f"share-{name}")
        self.comms.set_on_mail_callback(self._on_mail)
        self.cmd_var = self.name.upper() + "_CMD"
        self._sockets: dict[Address, socket.socket] = {}
        self._out: dict[bool, socket.socket] = {}
        self._summary: Timer | None = None
        self.start_time = self.clock.time()
        for text in outputs:
            self._configure(text, True, startup=True)
        for text in inputs:
            self._configure(text, False, startup=True)

    # ---- configuration -------------------------------------------------------------------------------------
    def _configure(self, text: str, is_output: bool, startup: bool = False) -> None:
        """Apply an Output/Input line or a PSHARE_CMD; a bad one is reported and skipped, as pShare does.

        An input route that cannot be bound at start-up is fatal (pShare exits too); at run time it is reported."""
        try:
            changes = self.table.add_config_line(text, is_output) if startup else self.table.add_io(text, is_output)
        except ShareError as exc:
            log.error("%s: %s; ignored", self.where if startup else self.cmd_var, exc)
            return
        self._apply(changes, startup)

    def _apply(self, changes: Changes, startup: bool) -> None:
        for route in changes.inputs:
            try:
                sock = _bind_input(route.address)
            except OSError as exc:
                del self.table.inputs[route.address]
                if startup:
                    raise MissionFileError(f"{self.where}: cannot listen on {route.address}: {exc}") from None
                log.error("%s: cannot listen on %s: %s", self.cmd_var, route.address, exc)
                continue
            self._sockets[route.address] = sock
            self.reactor.add_reader(sock, self._reader(sock, route))
            log.info("listening on %s%s", route.address, " (multicast)" if route.address.multicast else "")
        for address in changes.outputs:
            self._out_socket(address.multicast)
        if not startup:
            for var in changes.register:
                self.comms.register(var, 0.0)
            for var in changes.reregister:
                self.comms.unregister(var)
                self.comms.register(var, 0.0)
            for var_pattern, app_pattern in changes.wildcards:
                self.comms.register(var_pattern, app_pattern, 0.0)

    def _reader(self, sock: socket.socket, route: InputRoute) -> Callable[[], None]:
        return lambda: self._on_datagrams(sock, route)

    def _out_socket(self, multicast: bool) -> socket.socket:
        sock = self._out.get(multicast)
        if sock is None:
            sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4 * 64 * 1024)
            if multicast:
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
            sock.setblocking(False)
            self._out[multicast] = sock
        return sock

    # ---- running -------------------------------------------------------------------------------------------
    def after_close(self) -> None:
        for sock in [*self._sockets.values(), *self._out.values()]:
            sock.close()
        self.bad.flush(final=True)
        log.info("%s: %s", self.name, self.counters.describe())

    def on_connect(self) -> bool:
        """Every (re)connection: pShare's DoRegistrations, then the summaries (which follow them on the link)."""
        variables, wildcards = self.table.registrations()
        for var in variables:
            self.comms.register(var, 0.0)
        for var_pattern, app_pattern in wildcards:
            self.comms.register(var_pattern, app_pattern, 0.0)
        self.comms.register(self.cmd_var, 0.0)
        self._publish_summaries()
        if self._summary is None:
            self._summary = self.reactor.call_every(lambda: SUMMARY_PERIOD / self.clock.warp, self._publish_summaries)
        return True

    def _publish_summaries(self) -> None:
        self.comms.notify(SUMMARY_OUTPUT, self.table.output_summary())
        self.comms.notify(SUMMARY_INPUT, self.table.input_summary())
        self.bad.flush()

    # ---- DB -> UDP -----------------------------------------------------------------------------------------
    def _on_mail(self) -> bool:
        for msg in self.comms.fetch():
            if msg.raw_key == to_bytes(self.cmd_var):
                self._on_command(msg)
                continue
            for route in self.table.routes_for(msg):
                self._send(msg, route.dest_name, route.address)
        return True

    def _send(self, msg: MoosMessage, dest_name: str, address: Address) -> None:
        try:
            data = encode_datagram(msg, dest_name)
        except ShareError as exc:
            self.counters.send_failed += 1
            self.bad.warning(("too big", msg.key()), "not forwarding: %s", exc)
            return
        try:
            self._out_socket(address.multicast).sendto(data, address.sockaddr)
        except OSError as exc:
            self.counters.send_failed += 1
            self.bad.warning(("send", address), "cannot send %s to %s: %s", dest_name, address, exc)
            return
        self.counters.sent += 1

    def _on_command(self, msg: MoosMessage) -> None:
        """``cmd=output,...`` or ``cmd=input,...`` (pShare's OnCommandMsg; older than our start: ignored)."""
        if msg.msg_time < self.start_time:
            return
        text = msg.string()
        cmd = next((v for k, v in (p.partition("=")[::2] for p in text.replace(" ", "").split(","))
                    if k.lower() == "cmd"), "")
        if cmd.lower() not in ("output", "input"):
            log.error("%s: cmd=%r is neither \"output\" nor \"input\": %r ignored", self.cmd_var, cmd, text)
            return
        self._configure(text, cmd.lower() == "output")
        log.info("%s: %s applied", self.cmd_var, text)
        self._publish_summaries()

    # ---- UDP -> DB -----------------------------------------------------------------------------------------
    def _on_datagrams(self, sock: socket.socket, route: InputRoute) -> None:
        for _ in range(RECV_BURST):
            try:
                data, sender = sock.recvfrom(MAX_DATAGRAM)
            except BlockingIOError:
                return
            except OSError as exc:
                if exc.errno in (errno.EINTR, errno.ECONNREFUSED):
                    continue
                self.bad.error(("recv", route.address), "reading %s failed: %s", route.address, exc)
                return
            self.counters.received += 1
            try:
                msg = decode_datagram(data)
            except ShareError as exc:
                self.counters.malformed += 1
                self.bad.warning(("malformed", route.address), "%s: dropping a malformed datagram of %d bytes "
                                 "from %s:%d: %s", route.address, len(data), sender[0], sender[1], exc)
                continue
            if not route.wants(msg.raw_key) or self.comms.is_registered_for(msg.key()):
                self.counters.unwanted += 1
                continue
            if self.comms.post(msg, keep_source=True):
                self.counters.posted += 1
            else:
                self.counters.not_posted += 1
                self.bad.warning("db down", "not connected to the DB: dropping %s from %s", msg.key(), msg.source())


def main(argv: list[str] | None = None) -> int:
    args = parse_moos_app_args(argv, "moos-share", "A pShare-compatible MOOS variable sharer.", DEFAULT_APP_NAME)
    return serve(lambda: ShareApp(args.mission, alias=args.alias),
                 lambda app: (f"{app.name} connecting to {app.host}:{app.port}; outputs: "
                              f"{app.table.output_summary() or 'none'}; inputs: {app.table.input_summary() or 'none'}"),
                 "moos-share")


if __name__ == "__main__":
    raise SystemExit(main())
