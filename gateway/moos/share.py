"""pShare's datagrams and routing, as pure functions and tables (the app is ``gateway.apps.moos_share``).

Wire format (pShare of MOOS-IvP 19.8 and 24.8 alike, ``Share.cpp`` ``ApplyRoutes`` / ``Listener.cpp``): one UDP
datagram carries exactly one ``CMOOSMsg`` serialised by ``CMOOSMsg::Serialize`` (the layout of
:mod:`gateway.moos.codec`: ``int32 length, int32 id, char type, char data_type, str src, str aux, str community,
str key, f64 time, f64 dval, f64 dval2, str sval``), with no packet header, renamed to the route's ``dest_name`` and
otherwise as the sender's MOOSDB delivered it (source, aux source, community, time kept). pShare refuses to send a
message over ``MAX_UDP_SIZE`` (48 KiB).

Configuration (``ProcessConfig = pShare``; ``Output``/``Input`` may repeat)::

    Output = src_name = X, dest_name = Y, route = host:port & multicast_8 [, frequency = Hz]
             [, duration = s] [, max_shares = n]
    Output = X->Y:host:port@4.0 & Z:multicast_8          (short hand: anything without "route")
    Output = src_name = V*:GPS, dest_name = shared_, route = localhost:9201   (wildcard: var:app patterns)
    Input  = route = localhost:9201 & multicast_8 [, white_list = A*&B]
    multicast_base_port = 24460, multicast_address = 224.1.1.11

``<NAME>_CMD`` (``PSHARE_CMD``) takes ``cmd=output,<output fields>`` or ``cmd=input,<input fields>`` at run time.
"""

from __future__ import annotations

import math
import re
import socket
import time
from dataclasses import dataclass, field

from .codec import MESSAGE_FIXED_SIZE, decode_message, encode_message
from .errors import MoosError, ProtocolError
from .message import BINARY, DOUBLE, NOTIFY, STRING, MoosMessage, to_bytes
from .wildcard import wild_match

DEFAULT_MULTICAST_ADDRESS = "224.1.1.11"
DEFAULT_MULTICAST_BASE_PORT = 24460  # 24.8's DEFAULT_MULTICAST_GROUP_PORT; 19.8's 90000 wraps to 24464 in htons
MAX_MULTICAST_CHANNELS = 256
MAX_UDP_SIZE = 48 * 1024  # pShare does not send a message bigger than this
MAX_DATAGRAM = 65535  # what one recv can return (an IPv4 UDP payload is at most 65507 bytes)
MAX_FIELD = MAX_DATAGRAM  # no string field can be longer than the datagram holding it
SUMMARY_OUTPUT = "PSHARE_OUTPUT_SUMMARY"
SUMMARY_INPUT = "PSHARE_INPUT_SUMMARY"


class ShareError(MoosError):
    """A pShare configuration string or datagram that cannot be used (the text says why)."""


# ---- datagrams ---------------------------------------------------------------------------------------------
def encode_datagram(msg: MoosMessage, dest_name: str | bytes | None = None) -> bytes:
    """One datagram: ``msg`` (renamed to ``dest_name`` if given) as ``CMOOSMsg::Serialize`` writes it.

    ShareError if it would exceed ``MAX_UDP_SIZE`` (pShare refuses those too)."""
    if dest_name is not None:
        msg = msg.copy()
        msg.raw_key = to_bytes(dest_name)
    data = encode_message(msg)
    if len(data) > MAX_UDP_SIZE:
        raise ShareError(f"{msg.key()}: {len(data)} bytes exceed pShare's {MAX_UDP_SIZE}-byte payload limit")
    return data


def decode_datagram(data: bytes | bytearray | memoryview) -> MoosMessage:
    """The one message a datagram carries, every field checked; ShareError if it is not a usable notification.

    Stricter than pShare (which parses whatever the buffer holds and posts it): the message must fill the
    datagram exactly, be a notification (``N``) of a double, string or binary, name a variable, and carry a finite
    time."""
    raw = bytes(data)
    if len(raw) > MAX_DATAGRAM:
        raise ShareError(f"datagram of {len(raw)} bytes is over {MAX_DATAGRAM}")
    if len(raw) < MESSAGE_FIXED_SIZE:
        raise ShareError(f"datagram of {len(raw)} bytes is shorter than a message ({MESSAGE_FIXED_SIZE})")
    try:
        msg, end = decode_message(raw, 0, len(raw))
    except ProtocolError as exc:
        raise ShareError(f"not a CMOOSMsg: {exc}") from None
    if end != len(raw):
        raise ShareError(f"{len(raw) - end} stray bytes after the message")
    if msg.msg_type != NOTIFY:
        raise ShareError(f"message type {msg.msg_type!r} is not a notification")
    if msg.data_type not in (DOUBLE, STRING, BINARY):
        raise ShareError(f"data type {msg.data_type!r} is not D, S or B")
    if not msg.raw_key or b"\0" in msg.raw_key:
        raise ShareError("the message names no variable (or has a NUL in its name)")
    if not math.isfinite(msg.msg_time):
        raise ShareError(f"message time {msg.msg_time!r} is not finite")
    return msg


# ---- configuration strings --------------------------------------------------------------------------------
def parse_fields(text: str) -> dict[str, str]:
    """``tok=val,tok=val`` as ``MOOSValFromString`` reads it after ``MOOSRemoveChars(" ")``: names matched
    case-insensitively, the first occurrence wins."""
    fields: dict[str, str] = {}
    for part in re.sub(r"[ \t]+", "", text).split(","):
        name, eq, value = part.partition("=")
        if eq and name:
            fields.setdefault(name.lower(), value)
    return fields


def _number(fields: dict[str, str], name: str, default: float, where: str) -> float:
    text = fields.get(name)
    if text is None or text == "":
        return default
    try:
        value = float(text)
    except ValueError:
        raise ShareError(f"{where}: {name}={text!r} is not a number") from None
    if not math.isfinite(value):
        raise ShareError(f"{where}: {name}={text!r} is not finite")
    return value


@dataclass(frozen=True, order=True)
class Address:
    """A route's end point: ``host`` as configured (for summaries), ``ip`` resolved, ``port``, multicast or not."""

    host: str
    port: int
    ip: str
    multicast: bool = False
    channel: int = -1

    def __str__(self) -> str:
        return f"{self.host}:{self.port}"

    @property
    def sockaddr(self) -> tuple[str, int]:
        return (self.ip, self.port)


@dataclass
class ShareSettings:
    """``multicast_address`` / ``multicast_base_port``: what ``multicast_N`` means."""

    multicast_address: str = DEFAULT_MULTICAST_ADDRESS
    multicast_base_port: int = DEFAULT_MULTICAST_BASE_PORT

    def channel(self, n: int) -> Address:
        if not 0 <= n < MAX_MULTICAST_CHANNELS:
            raise ShareError(f"multicast_{n}: channels are 0..{MAX_MULTICAST_CHANNELS - 1}")
        port = self.multicast_base_port + n
        if port > 65535:
            raise ShareError(f"multicast_{n}: port {port} is over 65535 (multicast_base_port too high)")
        return Address(self.multicast_address, port, self.multicast_address, True, n)


def resolve_host(host: str) -> str:
    """The dotted IPv4 address of ``host`` (``localhost`` is 127.0.0.1); ShareError if it has none."""
    if host.lower() == "localhost":
        return "127.0.0.1"
    try:
        return socket.gethostbyname(host)
    except (OSError, UnicodeError) as exc:
        raise ShareError(f"cannot resolve host {host!r}: {exc}") from None


def parse_route(text: str, settings: ShareSettings) -> Address:
    """One route: ``host:port`` or ``multicast_N``."""
    if text.startswith("multicast_"):
        digits = text[len("multicast_"):]
        if not digits.isdigit():
            raise ShareError(f"route {text!r}: multicast_N needs a channel number")
        return settings.channel(int(digits))
    host, colon, port_text = text.rpartition(":")
    if not colon or not host or not port_text.isdigit():
        raise ShareError(f"route {text!r} is neither host:port nor multicast_N")
    port = int(port_text)
    if not 0 < port <= 65535:
        raise ShareError(f"route {text!r}: port {port} is not 1..65535")
    ip = resolve_host(host)
    multicast = 224 <= int(ip.split(".")[0]) <= 239
    return Address(host, port, ip, multicast)


def parse_routes(text: str, settings: ShareSettings) -> list[Address]:
    """``route & route & ...`` (empty parts skipped, as ``MOOSChomp`` does)."""
    routes = [parse_route(part, settings) for part in text.split("&") if part]
    if not routes:
        raise ShareError("route names no destination")
    return routes


@dataclass
class Route:
    """One output share (pShare's ``Route``): rate, duration and count limits as ``Route::IsActive``."""

    src_name: str
    dest_name: str
    address: Address
    frequency: float = 0.0
    duration: float = -1.0  # <0: no limit
    max_shares: int = -1  # <0: no limit
    created: float = field(default_factory=time.monotonic)
    last_sent: float = -math.inf
    shares: int = 0

    def same(self, other: Route) -> bool:
        """``Route::operator==``: same address, names and kind (limits may differ)."""
        return (self.address, self.dest_name, self.src_name) == (other.address, other.dest_name, other.src_name)

    def is_active(self, now: float) -> bool:
        if self.duration == 0.0 and (self.max_shares < 0 or self.shares < self.max_shares):
            return True
        if self.duration >= 0.0 and now - self.created > self.duration:
            return False
        if self.max_shares >= 0 and self.shares >= self.max_shares:
            return False
        return not (self.frequency > 0.0 and now - self.last_sent < 1.0 / self.frequency)


@dataclass
class WildcardShare:
    """``src_name = var_pattern[:app_pattern]``: a route is made per matching variable when it first arrives."""

    var_pattern: str
    app_pattern: str
    template: Route  # dest_name: a prefix, "" or "^" (the part the single * matched)

    def dest_for(self, key: str) -> str:
        dest = self.template.dest_name
        if dest == "^" and self.var_pattern.count("*") == 1:
            if self.var_pattern.startswith("*"):
                return key[: len(key) - (len(self.var_pattern) - 1)] if key.endswith(self.var_pattern[1:]) else key
            if self.var_pattern.endswith("*"):
                return key[len(self.var_pattern) - 1:]
        return dest + key


@dataclass
class InputRoute:
    address: Address
    white_list: list[str] = field(default_factory=list)

    def wants(self, key: bytes) -> bool:
        return not self.white_list or any(wild_match(to_bytes(p), key) for p in self.white_list)


@dataclass
class Changes:
    """What a configuration string changed: variables to register, wildcards to register, inputs to open."""

    register: list[str] = field(default_factory=list)
    reregister: list[str] = field(default_factory=list)  # duration=0 restated: unregister + register (send latest)
    wildcards: list[tuple[str, str]] = field(default_factory=list)
    inputs: list[InputRoute] = field(default_factory=list)
    outputs: list[Address] = field(default_factory=list)


class ShareTable:
    """pShare's routing table, wildcard table and listeners, fed with configuration strings."""

    def __init__(self, settings: ShareSettings | None = None) -> None:
        self.settings = settings or ShareSettings()
        self.routes: dict[str, list[Route]] = {}
        self.wildcards: list[WildcardShare] = []
        self.inputs: dict[Address, InputRoute] = {}
        self._now = time.monotonic

    # ---- configuration ------------------------------------------------------------------------------------
    def add_config_line(self, text: str, is_output: bool) -> Changes:
        """An ``Output``/``Input`` value as pShare's ``OnStartUp`` takes it (short hand unless it says route)."""
        if is_output and "route" not in text.lower():
            return self.add_shorthand_output(text)
        return self.add_io(text, is_output)

    def add_io(self, text: str, is_output: bool) -> Changes:
        """``ProcessIOConfigurationString``: long hand ``src_name=..,dest_name=..,route=..`` (or ``route=..``)."""
        fields = parse_fields(text)
        where = f"{'output' if is_output else 'input'} {text.strip()!r}"
        routes_text = fields.get("route")
        if routes_text is None:
            raise ShareError(f"{where}: \"route\" is a required field")
        addresses = parse_routes(routes_text, self.settings)
        changes = Changes()
        if not is_output:
            white = [p for p in fields.get("white_list", "").split("&") if p]
            for address in addresses:
                if address in self.inputs:
                    raise ShareError(f"{where}: already listening on {address}")
                route = InputRoute(address, white)
                self.inputs[address] = route
                changes.inputs.append(route)
            return changes
        src = fields.get("src_name")
        if not src:
            raise ShareError(f"{where}: \"src_name\" is a required field")
        dest = fields.get("dest_name") or src
        frequency = _number(fields, "frequency", 0.0, where)
        duration = _number(fields, "duration", -1.0, where)
        max_shares = int(_number(fields, "max_shares", -1, where))
        if frequency < 0:
            raise ShareError(f"{where}: frequency must not be negative")
        for address in addresses:
            self._add_output(src, dest, address, frequency, duration, max_shares, changes)
        return changes

    def add_shorthand_output(self, text: str) -> Changes:
        """``X->Y:host:port@Hz & Z:multicast_8 & host:port`` (``ProcessShortHandIOConfigurationString``)."""
        where = f"output {text.strip()!r}"
        src, arrow, rest = text.partition("->")
        src = src.strip()
        if not arrow or not src:
            raise ShareError(f"{where}: short hand needs 'src->route'")
        changes = Changes()
        for whole in (p.strip() for p in rest.split("&")):
            if not whole:
                continue
            description, _, freq_text = whole.partition("@")
            try:
                frequency = float(freq_text) if freq_text.strip() else 0.0
            except ValueError:
                frequency = 0.0  # pShare: a non-numeric @frequency means every notification
            parts = [p.strip() for p in description.split(":")]
            dest = src
            if parts[-1].startswith("multicast_"):
                if len(parts) > 2:
                    raise ShareError(f"{where}: too many parts in {description!r}")
                if len(parts) == 2:
                    dest = parts[0]
                route = parts[-1]
            else:
                if len(parts) < 2 or len(parts) > 3:
                    raise ShareError(f"{where}: {description!r} is not [dest:]host:port or [dest:]multicast_N")
                if len(parts) == 3:
                    dest = parts.pop(0)
                route = f"{parts[0]}:{parts[1]}"
            address = parse_route(route, self.settings)
            self._add_output(src, dest, address, max(0.0, frequency), -1.0, -1, changes)
        return changes

    def _add_output(self, src: str, dest: str, address: Address, frequency: float, duration: float,
                    max_shares: int, changes: Changes) -> None:
        src, dest = src.strip(), dest.strip()
        if address not in changes.outputs:
            changes.outputs.append(address)
        route = Route(src, dest, address, frequency, duration, max_shares, created=self._now())
        if not any(c in src for c in "*?:"):
            existing = self.routes.setdefault(src, [])
            for i, old in enumerate(existing):
                if old.same(route):
                    if duration == 0.0:  # restated with duration=0: send the DB's latest value once
                        route.max_shares = 1
                        route.duration = math.inf
                        changes.reregister.append(src)
                    existing[i] = route
                    return
            existing.append(route)
            changes.register.append(src)
            return
        if any(c in dest for c in "*?"):
            dest = ""  # no renaming asked for
        route.dest_name = dest
        var_pattern, _, app_pattern = src.partition(":")
        app_pattern = app_pattern or "*"
        for share in self.wildcards:
            if (share.var_pattern, share.app_pattern) == (var_pattern, app_pattern) and share.template.same(route):
                share.template = route
                return
        self.wildcards.append(WildcardShare(var_pattern, app_pattern, route))
        changes.wildcards.append((var_pattern, app_pattern))

    def registrations(self) -> tuple[list[str], list[tuple[str, str]]]:
        """What to register with the DB on every connection (``DoRegistrations``)."""
        return sorted(self.routes), sorted({(w.var_pattern, w.app_pattern) for w in self.wildcards})

    # ---- routing -------------------------------------------------------------------------------------------
    def routes_for(self, msg: MoosMessage) -> list[Route]:
        """The routes ``msg`` goes out on now (``ApplyRoutes``; wildcard routes are made on first sight)."""
        key = msg.key()
        routes = self.routes.get(key)
        if routes is None:
            made = []
            source = msg.raw_src
            for share in self.wildcards:
                if wild_match(to_bytes(share.app_pattern), source) and wild_match(to_bytes(share.var_pattern),
                                                                                  msg.raw_key):
                    t = share.template
                    made.append(Route(key, share.dest_for(key), t.address, t.frequency, t.duration, t.max_shares,
                                      created=self._now()))
            if not made:
                return []
            routes = self.routes[key] = made
        now = self._now()
        active = [r for r in routes if r.is_active(now)]
        for route in active:
            route.last_sent = now
            route.shares += 1
        return active

    def input_for(self, address: Address) -> InputRoute | None:
        return self.inputs.get(address)

    # ---- summaries -----------------------------------------------------------------------------------------
    def output_summary(self) -> str:
        """``PSHARE_OUTPUT_SUMMARY``: ``X->Y:host:port & Z:host:port:multicast_8, K->...``."""
        items = []
        for src in sorted(self.routes):
            parts = []
            for r in self.routes[src]:
                text = f"{r.dest_name}:{r.address}"
                if r.address.channel >= 0:
                    text += f":multicast_{r.address.channel}"
                parts.append(text)
            items.append(f"{src}->" + " & ".join(parts))
        return ", ".join(items)

    def input_summary(self) -> str:
        """``PSHARE_INPUT_SUMMARY``: ``host:port,224.1.1.11:24468:multicast_8``."""
        items = []
        for address in sorted(self.inputs):
            text = str(address)
            if address.channel >= 0:
                text += f":multicast_{address.channel}"
            items.append(text)
        return ",".join(items)
