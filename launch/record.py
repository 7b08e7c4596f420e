"""What a mission did, in sim seconds: the track and every interesting posting.

``launch.recorder`` fills a ``MissionRecord`` from the mission's logs (goby-logger's .goby, moos-logger's .alog);
the analyses and pictures read it. Kept free of I/O so analyses are testable with hand-made records.
"""

from __future__ import annotations

import csv
import threading
from dataclasses import dataclass, field
from pathlib import Path

#: The modules of the missions' own messages (the course's, the frontseat's, and every application's configuration,
#: which each publishes on ``goby::configuration``): goby-logger imports them (``load_shared_library``) so its logs
#: describe every type they hold (the MCAP export decodes everything), and the demos' log reader decodes with them.
PROTO_MODULES = (
    "frontseat.protobuf.frontseat_pb2",
    "frontseat.protobuf.frontseat_data_pb2",
    "frontseat.protobuf.navigation_pb2",
    "translators.trail.protobuf.nav_dccl_pb2",
    "translators.trail.protobuf.health_status_pb2",
    "translators.usv.protobuf.command_dccl_pb2",
    "translators.usv.protobuf.command_ack_pb2",
    "gateway.goby.intervehicle.protobuf.intervehicle_pb2",
    "gateway.goby.portal.protobuf.coroner_pb2",
    # configurations
    "frontseat.protobuf.frontseat_interface_config_pb2",
    "frontseat.protobuf.opencpn_config_pb2",
    "gateway.goby.portal.protobuf.coroner_config_pb2",
    "gateway.goby.portal.protobuf.gobyd_config_pb2",
    "gateway.goby.portal.protobuf.terminate_config_pb2",
    "gateway.moos_gateway.protobuf.moos_gateway_config_pb2",
    "launch.liaison.protobuf.liaison_config_pb2",
    "translators.trail.protobuf.health_monitor_config_pb2",
    "translators.trail.protobuf.manager_config_pb2",
    "translators.usv.protobuf.usv_config_pb2",
    "behaviors.protobuf.goby_helm_example_config_pb2",
)


def load_shared_library_lines() -> str:
    """goby-logger's ``load_shared_library`` lines for :data:`PROTO_MODULES`."""
    return "\n".join(f'load_shared_library: "{module}"' for module in PROTO_MODULES)


#: Where ``MissionRecord.add_nav`` keeps each NAV_* variable's latest value.
_NAV_ATTRIBUTES = {"NAV_X": "_x", "NAV_Y": "_y", "NAV_HEADING": "_heading", "NAV_SPEED": "_speed", "NAV_DEPTH": "_depth"}


@dataclass(frozen=True)
class NavSample:
    """One vehicle position (local metres), heading (deg) and speed (m/s) at sim time ``t``."""

    t: float
    x: float
    y: float
    heading: float | None = None
    speed: float | None = None
    depth: float | None = None


@dataclass(frozen=True)
class Event:
    """A posting seen at sim time ``t``: a MOOS variable, an interface state, a command acknowledgement."""

    t: float
    source: str  # "moos", "interface", "ack"
    name: str
    value: str
    origin: str = ""  # the MOOS source (poster) or responder


@dataclass
class MissionRecord:
    """The track and events, appended from recorder threads; read after the mission (or via snapshot())."""

    nav: list[NavSample] = field(default_factory=list)
    events: list[Event] = field(default_factory=list)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    _x: float | None = field(default=None, repr=False)
    _y: float | None = field(default=None, repr=False)
    _heading: float | None = field(default=None, repr=False)
    _speed: float | None = field(default=None, repr=False)
    _depth: float | None = field(default=None, repr=False)

    def add_nav(self, t: float, name: str, value: float) -> None:
        """Fold one NAV_* value in; a position row is added (or its newest row updated) per update."""
        attribute = _NAV_ATTRIBUTES.get(name)
        if attribute is None:
            return
        with self._lock:
            setattr(self, attribute, value)
            if self._x is None or self._y is None:
                return
            sample = NavSample(t, self._x, self._y, self._heading, self._speed, self._depth)
            if self.nav and abs(self.nav[-1].t - t) < 1e-6:
                self.nav[-1] = sample
            else:
                self.nav.append(sample)

    def add_event(self, t: float, source: str, name: str, value: str, origin: str = "") -> None:
        with self._lock:
            self.events.append(Event(t, source, name, value, origin))

    def sort(self) -> None:
        """Put the track and the events in time order (stable: same-time items keep their order), for a record
        filled from several logs."""
        with self._lock:
            self.nav.sort(key=lambda s: s.t)
            self.events.sort(key=lambda e: e.t)

    def snapshot(self) -> tuple[list[NavSample], list[Event]]:
        with self._lock:
            return list(self.nav), list(self.events)

    def events_named(self, name: str, source: str | None = None) -> list[Event]:
        with self._lock:
            return [e for e in self.events if e.name == name and (source is None or e.source == source)]

    def write_csv(self, track_path: Path, events_path: Path | None = None) -> None:
        """track.csv: t,x,y,heading,speed,deploy_state; events.csv: t,source,name,value,origin."""
        nav, events = self.snapshot()
        deploy = [(e.t, e.value) for e in events if e.name == "DEPLOY_STATE"]
        with open(track_path, "w", newline="") as out:
            writer = csv.writer(out)
            writer.writerow(["t", "x", "y", "heading", "speed", "deploy_state"])
            index, state = 0, ""
            for s in nav:
                while index < len(deploy) and deploy[index][0] <= s.t:
                    state = deploy[index][1]
                    index += 1
                writer.writerow([f"{s.t:.2f}", f"{s.x:.2f}", f"{s.y:.2f}", _fmt(s.heading), _fmt(s.speed), state])
        if events_path is not None:
            with open(events_path, "w", newline="") as out:
                writer = csv.writer(out)
                writer.writerow(["t", "source", "name", "value", "origin"])
                for e in events:
                    writer.writerow([f"{e.t:.2f}", e.source, e.name, e.value, e.origin])


def _fmt(value: float | None) -> str:
    return "" if value is None else f"{value:.2f}"


def until(record: MissionRecord, end: float) -> MissionRecord:
    """A copy without what came after ``end`` (the logs go on while the processes stop)."""
    nav, events = record.snapshot()
    out = MissionRecord()
    out.nav = [s for s in nav if s.t <= end]
    out.events = [e for e in events if e.t <= end]
    return out


def shifted(record: MissionRecord, dt: float) -> MissionRecord:
    """A copy with every time moved by ``-dt`` (so t=0 can be the moment the helm took command)."""
    nav, events = record.snapshot()
    out = MissionRecord()
    out.nav = [NavSample(s.t - dt, s.x, s.y, s.heading, s.speed, s.depth) for s in nav]
    out.events = [Event(e.t - dt, e.source, e.name, e.value, e.origin) for e in events]
    return out
