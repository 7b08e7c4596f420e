"""The trail mission's settings and identities, in one place: every generated config reads them from here.

Two kinds of input, as in the Goby3 course's ``launch/trail/config``:

* the course's own environment variables, ``goby3_course_n_auvs`` (usv, auv) and ``goby3_course_auv_index``
  (auv), which ``all.launch`` sets per nested launch; a missing one is the course's INVALID CONFIGURATION;
* ``TRAIL_*`` variables for what the course hard-codes (run directory, warp, origin, port bases, the choice of
  MOOSDB and helms), so a test or the demo can run a mission on free ports; unset ones keep the course's values.

Identities follow the course's ``common/vehicle.py`` and ``common/comms.py``: vehicle id 0 topside, 1 usv,
2+i auv i; MOOS port 9000+id, simulator port 55000+id, liaison port 50000+id; satellite modem id+1, acomms
modem id+1+256 under subnet mask 0xFF00; acomms TDMA slots alternating USV (258) and each AUV (259+i).

``acomms_channel`` / ``satellite_channel`` (``TRAIL_ACOMMS_CHANNEL``, ``TRAIL_SATELLITE_CHANNEL``) impair a link:
the text of our ``channel_model`` extension of its driver block (``loss: 0.2 delay_min: 1 delay_max: 3``), which
every node of the link applies to what it receives (docs/intervehicle.md "Lossy channels"); empty: lossless.
"""

from __future__ import annotations

import ipaddress
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

from google.protobuf import text_format

from gateway.goby.acomms.channel import ChannelModel, check_channel_model
from gateway.goby.acomms.errors import ModemConfigError
from launch.config import EnvSettings, check_warp_and_origin, env_variables
from launch.errors import MissionConfigError

REPO_ROOT = Path(__file__).resolve().parents[2]
TRAIL_DIR = Path(__file__).resolve().parent
KAUAI_ORIGIN = (21.590491, -159.534166)

N_AUVS_VAR = "goby3_course_n_auvs"
AUV_INDEX_VAR = "goby3_course_auv_index"
PLATFORM_KINDS = ("topside", "usv", "auv")

# common/comms.py
SUBNET_MASK = 0xFF00
SUBNET_INDEX = {"satellite": 0, "acomms": 1}
MODEMS_IN_SUBNET = 256
USV_VEHICLE_ID = 1
TOPSIDE_VEHICLE_ID = 0
SATELLITE_SLOT = (5, 64)  # slot_seconds, max_frame_bytes (post-homework2 onward)
ACOMMS_SLOT = (10, 128)
MULTICAST_ADDRESS = "239.142.0.2"

# The topside's default plan (sim seconds after the USV is under helm command): polygon, then waypoints.
DEFAULT_SCHEDULE = "0:polygon:6:200,400:waypoints"

_ENV = env_variables("TRAIL_", (
    "run_dir", "warp", "lat_origin", "lon_origin", "moos_port_base", "sim_port_base", "liaison_port_base",
    "satellite_port", "acomms_port", "moosdb", "helm", "usv_helm", "liaison_address", "link_address", "schedule",
    "socket_dir",
    "east_duration", "south_duration", "acomms_channel", "satellite_channel", "moos_address", "broker_address",
    "broker_port", "link_peers", "ais_address", "ais_port", "share_port_base", "usv_address", "goby_logger"))
CHANNEL_LINKS = ("satellite", "acomms")


@dataclass(frozen=True)
class TrailSettings(EnvSettings):
    """What every process of every platform must agree on: warp, origin, port bases, program choices."""

    ENV: ClassVar[Mapping[str, str]] = _ENV

    run_dir: Path = Path("/tmp/goby3_course_trail")
    warp: int = 5  # common/sim.py
    lat_origin: float = KAUAI_ORIGIN[0]
    lon_origin: float = KAUAI_ORIGIN[1]
    moos_port_base: int = 9000
    sim_port_base: int = 55000
    liaison_port_base: int = 50000
    satellite_port: int = 54500
    acomms_port: int = 54501
    moosdb: str = "moos-db"  # or MOOSDB
    helm: str = "ivp-helm"  # or pHelmIvP (the MOOS helm of every vehicle that runs one)
    # or goby_logger (Goby3's), whose load_shared_library are shared libraries: ours names Python modules there
    goby_logger: str = "goby-logger"
    usv_helm: str = "ivp"  # ivp: the MOOS helm with usv.bhv; goby: homework 3's goby-helm-example
    liaison_address: str = "127.0.0.1"  # the course binds 0.0.0.0; the page has no login, so loopback unless asked
    # the links' listen_address: loopback keeps every datagram on this machine; the course leaves Goby's default
    # 0.0.0.0 (the default interface), which a real gobyd in the mission needs (docs/intervehicle.md)
    link_address: str = "127.0.0.1"
    schedule: str = DEFAULT_SCHEDULE
    socket_dir: Path = Path("")  # where the brokers' IPC sockets go (default: run_dir); AF_UNIX paths are short
    east_duration: int = 500  # homework helm legs (goby3_course_helm.pb.cfg.in)
    south_duration: int = 200
    acomms_channel: str = ""  # channel_model text for the acoustic link ("": lossless)
    satellite_channel: str = ""  # ... for the satellite link
    # One platform per host (docs/hosts.md): where the MOOSDB listens and the MOOS apps connect (loopback on one
    # machine; the host's address when another computer of the vehicle, or the demo's console, reaches it) ...
    moos_address: str = "127.0.0.1"
    # ... the interprocess transport: "" IPC (socket_dir), else Goby's TCP transport, the broker binding this
    # address and port and every app of the vehicle connecting there (a vehicle of two computers)
    broker_address: str = ""
    broker_port: int = 11144  # Goby's default tcp_port
    # ... and the sources the links accept (our udp_peers extension): comma-separated addresses or networks of
    # the peers' computers ("": any on a host address, loopback only on 127.0.0.1)
    link_peers: str = ""
    # The topside's goby-opencpn-interface: AIS sentences for OpenCPN on this TCP address and port (the course's
    # 54000; loopback unless asked, docs/opencpn.md)
    ais_address: str = "127.0.0.1"
    ais_port: int = 54000
    # moos-share (pShare's role): each vehicle's input port is share_port_base + its vehicle id; the AUVs send
    # NODE_REPORT_LOCAL as NODE_REPORT to the USV's, on usv_address (the USV's host; loopback on one machine)
    share_port_base: int = 9300
    usv_address: str = "127.0.0.1"

    def __post_init__(self) -> None:
        check_warp_and_origin(self.warp, self.lat_origin, self.lon_origin)
        for link in CHANNEL_LINKS:
            self.channel_model(link)  # a bad one is a MissionConfigError naming the variable and the field
        if self.usv_helm not in ("ivp", "goby"):
            raise MissionConfigError(f"TRAIL_USV_HELM must be ivp or goby, not {self.usv_helm!r}")
        for name in ("link_address", "moos_address", "ais_address", "usv_address",
                     *(("broker_address",) if self.broker_address else ())):
            try:
                ipaddress.IPv4Address(getattr(self, name))
            except ValueError:
                raise MissionConfigError(f"{_ENV[name]} must be an IPv4 address, not {getattr(self, name)!r}") from None
        self.peer_networks()
        for name in ("broker_port", "ais_port"):
            if not 0 < getattr(self, name) < 65536:
                raise MissionConfigError(f"{_ENV[name]} {getattr(self, name)} is not a TCP port")
        for name in ("moos_port_base", "sim_port_base", "liaison_port_base", "satellite_port", "acomms_port",
                     "share_port_base"):
            port = getattr(self, name)
            if not 0 < port < 65536 - 256:
                raise MissionConfigError(f"{name} {port} is not a TCP/UDP port with room for 256 vehicles")

    def channel_model(self, link: str) -> ChannelModel | None:
        """The checked channel model of ``link`` (satellite or acomms), or None for a lossless link."""
        text = getattr(self, f"{link}_channel").strip()
        if not text:
            return None
        model = ChannelModel()
        var = _ENV[f"{link}_channel"]
        try:
            text_format.Parse(text, model)
            check_channel_model(model)
        except (text_format.ParseError, ModemConfigError) as exc:
            raise MissionConfigError(f"{var}={text!r}: {exc}") from None
        return model

    def peer_networks(self) -> list[str]:
        """``link_peers`` as networks (an address is its /32); MissionConfigError naming a bad one."""
        out = []
        for text in filter(None, (part.strip() for part in self.link_peers.split(","))):
            try:
                out.append(str(ipaddress.IPv4Network(text, strict=False)))
            except ValueError:
                raise MissionConfigError(f"TRAIL_LINK_PEERS: {text!r} is not an IPv4 address or network") from None
        return out

    @property
    def sockets(self) -> Path:
        return self.socket_dir if str(self.socket_dir) not in ("", ".") else self.run_dir


@dataclass(frozen=True)
class Vehicle:
    """One platform of the mission: its kind, index, and the ids and ports derived from them."""

    kind: str  # topside, usv, auv
    n_auvs: int = 0
    index: int = 0  # AUV index (auv only)

    def __post_init__(self) -> None:
        if self.kind not in PLATFORM_KINDS:
            raise MissionConfigError(f"platform {self.kind!r} is not one of {', '.join(PLATFORM_KINDS)}")
        if self.n_auvs < 0 or self.n_auvs > 250:
            raise MissionConfigError(f"{N_AUVS_VAR}={self.n_auvs} is not between 0 and 250")
        if self.kind == "auv" and not 0 <= self.index < self.n_auvs:
            raise MissionConfigError(f"{AUV_INDEX_VAR}={self.index} is not below {N_AUVS_VAR}={self.n_auvs}")

    @property
    def name(self) -> str:
        """The interprocess platform and launcher prefix: ``topside``, ``usv``, ``auv<i>``."""
        return f"auv{self.index}" if self.kind == "auv" else self.kind

    @property
    def vehicle_id(self) -> int:
        return {"topside": TOPSIDE_VEHICLE_ID, "usv": USV_VEHICLE_ID}.get(self.kind, self.index + 2)

    @property
    def display_name(self) -> str:
        """What nav_convert's ``vehicle_name()`` calls it: ``USV``, ``AUV_<i>``, ``TOPSIDE``."""
        return {"topside": "TOPSIDE", "usv": "USV"}.get(self.kind, f"AUV_{self.index}")

    @property
    def community(self) -> str:
        """The MOOS community (the course hard-codes ``trail_usv``; AUVs are ``AUV<i>``)."""
        return "trail_usv" if self.kind == "usv" else f"AUV{self.index}"

    @property
    def satellite_modem_id(self) -> int:
        return satellite_modem_id(self.vehicle_id)

    @property
    def acomms_modem_id(self) -> int:
        return acomms_modem_id(self.vehicle_id)

    @property
    def links(self) -> tuple[str, ...]:
        """The intervehicle links its gobyd runs: topside satellite, USV both, AUV acomms."""
        return {"topside": ("satellite",), "usv": ("satellite", "acomms")}.get(self.kind, ("acomms",))

    @property
    def trail_angle(self) -> float:
        """auv.bhv's relative trail angle: 90 + 180/(n-1)*i; the course divides by zero for n = 1, we trail astern."""
        if self.n_auvs < 2:
            return 180.0
        return 90.0 + (270.0 - 90.0) / (self.n_auvs - 1) * self.index

    @property
    def deploy_depth(self) -> float:
        return 10.0 + 10.0 * self.index

    def moos_port(self, settings: TrailSettings) -> int:
        return settings.moos_port_base + self.vehicle_id

    def share_port(self, settings: TrailSettings) -> int:
        """Where this vehicle's moos-share listens (only the USV's does: the AUVs' NODE_REPORTs)."""
        return settings.share_port_base + self.vehicle_id

    def sim_port(self, settings: TrailSettings) -> int:
        return settings.sim_port_base + self.vehicle_id

    def liaison_port(self, settings: TrailSettings) -> int:
        return settings.liaison_port_base + self.vehicle_id

    def ipc_base(self, settings: TrailSettings) -> str:
        return str(settings.sockets / f"goby_{self.name}")

    def moos_file(self, settings: TrailSettings) -> Path:
        return settings.run_dir / f"{self.name}.moos"

    def bhv_file(self, settings: TrailSettings) -> Path:
        return settings.run_dir / f"{self.name}.bhv"

    def log_dir(self, settings: TrailSettings) -> Path:
        """Debug logs per platform, as the course's ``logs/topside``, ``logs/usv``, ``logs/auv/<i>``."""
        tail = Path("auv") / str(self.index) if self.kind == "auv" else Path(self.kind)
        return settings.run_dir / "logs" / tail


def channel_text(loss: float = 0.0, delay: tuple[float, float] = (0.0, 0.0), outage: tuple[float, float] | None = None,
                 seed: int | None = None) -> str:
    """A link's ``channel_model`` text: ``loss`` (0..1), ``delay`` (min, max seconds), ``outage`` (duration, period
    seconds), ``seed``; "" when nothing is impaired (a lossless link has no channel model at all)."""
    parts = []
    if loss:
        parts.append(f"loss: {loss:g}")
    if delay[1] > 0:
        parts.append(f"delay_min: {delay[0]:g} delay_max: {delay[1]:g}")
    if outage is not None and outage[0] > 0:
        parts.append(f"outage_period: {outage[1]:g} outage_duration: {outage[0]:g}")
    if parts and seed is not None:
        parts.append(f"seed: {seed}")
    text = " ".join(parts)
    if any(not math.isfinite(x) for x in (loss, *delay, *(outage or ()))):
        raise MissionConfigError(f"channel settings must be finite numbers: {text}")
    return text


def satellite_modem_id(vehicle_id: int) -> int:
    return SUBNET_INDEX["satellite"] * MODEMS_IN_SUBNET + vehicle_id + 1


def acomms_modem_id(vehicle_id: int) -> int:
    return SUBNET_INDEX["acomms"] * MODEMS_IN_SUBNET + vehicle_id + 1


def auv_modem_ids(n_auvs: int) -> list[int]:
    return [acomms_modem_id(i + 2) for i in range(n_auvs)]


def acomms_mac_slots(n_auvs: int) -> list[tuple[int, int, int]]:
    """(src, slot_seconds, max_frame_bytes) per slot: for each AUV, a USV slot and then that AUV's slot."""
    usv = acomms_modem_id(USV_VEHICLE_ID)
    seconds, size = ACOMMS_SLOT
    slots: list[tuple[int, int, int]] = []
    for modem in auv_modem_ids(n_auvs):
        slots += [(usv, seconds, size), (modem, seconds, size)]
    return slots


def satellite_mac_slots() -> list[tuple[int, int, int]]:
    seconds, size = SATELLITE_SLOT
    return [(satellite_modem_id(TOPSIDE_VEHICLE_ID), seconds, size), (satellite_modem_id(USV_VEHICLE_ID), seconds, size)]


def _env_int(environ: Mapping[str, str], var: str, why: str) -> int:
    raw = environ.get(var)
    if raw is None or raw == "":
        raise MissionConfigError(f"environment variable {var} must be set ({why})")
    try:
        return int(raw)
    except ValueError:
        raise MissionConfigError(f"{var}={raw!r} is not a whole number") from None


def vehicle_from_env(kind: str, environ: Mapping[str, str] | None = None) -> Vehicle:
    """The platform a config line is for; the course's variables are required where the course requires them."""
    environ = os.environ if environ is None else environ
    if kind == "topside":
        raw = environ.get(N_AUVS_VAR, "")
        return Vehicle("topside", int(raw) if raw.isdigit() else 0)
    if kind not in PLATFORM_KINDS:
        raise MissionConfigError(f"platform {kind!r} is not one of {', '.join(PLATFORM_KINDS)}")
    n_auvs = _env_int(environ, N_AUVS_VAR, "the number of AUVs")
    index = _env_int(environ, AUV_INDEX_VAR, "this AUV's index, 0..n-1") if kind == "auv" else 0
    return Vehicle(kind, n_auvs, index)
