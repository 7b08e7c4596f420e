"""goby-liaison's configuration, checked: everything a config names must exist before the page is served.

Reads Goby's ``LiaisonConfig`` and our extension ``[goby_moos_py.liaison.protobuf.web]``; imports the message
modules it names; refuses (LiaisonConfigError naming the field) a type that cannot be found, a bad regex, a
target layer this build cannot publish on, ``load_proto_file``/``load_proto_dir`` (no .proto compiler at run
time here: compile and import instead), a number out of its range (``http_port: 70000`` would wrap to 4464
at bind time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from google.protobuf.message import Message

from gateway.goby.portal.marshalling import is_dccl
from gateway.goby.protobuf.layer_pb2 import LAYER_INTERVEHICLE
from launch.liaison.commander_model import CommandType, Target
from launch.liaison.errors import LiaisonConfigError
from launch.liaison.message_types import find_message_type, import_project_protos, load_message_modules
from launch.liaison.name_filter import compile_filter
from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig, ProtobufCommanderConfig
from launch.liaison.protobuf.liaison_web_pb2 import InterProcessAck, WebConfig, web

Point = tuple[float, float]


@dataclass
class LiaisonSettings:
    """What the server and the portal thread need, derived once from the config."""

    title: str
    http_address: str
    http_port: int
    update_freq: float
    start_paused: bool
    views: dict[str, bool]
    group_filter: str
    type_filter: str
    max_history: int
    max_message_size: int
    history_groups: list[str]
    command_types: list[CommandType]
    notify: list[tuple[str, str]]
    waypoints: list[Point] = field(default_factory=list)
    polygon: list[Point] = field(default_factory=list)
    center_activate: bool = False
    trail_points: int = 600
    client_queue: int = 16
    max_clients: int = 64
    max_rows: int = 5000
    command_history: int = 200
    allowed_hosts: list[str] = field(default_factory=list)
    initial_mode: str | None = None
    datum: tuple[float, float] | None = None  # (lat, lon) of the local grid's origin
    moos: MoosEndpoint | None = None
    background: BackgroundImage | None = None
    replay_dirs: list[Path] = field(default_factory=list)
    replay_max_samples: int = 200_000


@dataclass(frozen=True)
class MoosEndpoint:
    """The MOOSDB the map reads the helm's VIEW_* postings from."""

    host: str
    port: int
    name: str


@dataclass(frozen=True)
class BackgroundImage:
    """A configured image of the operating area and the lat/lon of its edges (pMarineViewer's .info)."""

    path: Path
    lat_north: float
    lat_south: float
    lon_east: float
    lon_west: float


def web_config(cfg: LiaisonConfig) -> WebConfig:
    return cfg.Extensions[web]


def _targets(load: ProtobufCommanderConfig.LoadProtobuf, cls: type[Message], where: str) -> tuple[Target, ...]:
    targets = []
    for index, entry in enumerate(load.publish_to):
        numeric_field = entry.group_numeric_field_name if entry.HasField("group_numeric_field_name") else ""
        if numeric_field and numeric_field not in cls.DESCRIPTOR.fields_by_name:
            raise LiaisonConfigError(f"{where}.publish_to[{index}]: {cls.DESCRIPTOR.full_name} has no field "
                                     f"{numeric_field!r} (group_numeric_field_name)")
        if entry.layer == LAYER_INTERVEHICLE and not is_dccl(cls):
            raise LiaisonConfigError(f"{where}.publish_to[{index}]: {cls.DESCRIPTOR.full_name} is not a DCCL message "
                                     "(LAYER_INTERVEHICLE sends DCCL only)")
        if not entry.group.strip():
            raise LiaisonConfigError(f"{where}.publish_to[{index}]: empty group")
        targets.append(Target(index, entry.group, entry.group_numeric, numeric_field, entry.layer))
    return tuple(targets)


def _ack_rules(rules: list[InterProcessAck]) -> dict[str, InterProcessAck]:
    out = {}
    for index, rule in enumerate(rules):
        where = f"[goby_moos_py.liaison.protobuf.web].interprocess_ack[{index}]"
        command = find_message_type(rule.command_type)
        ack = find_message_type(rule.ack_type)
        for cls, name, what in ((command, rule.command_field, "command_field"), (ack, rule.ack_field, "ack_field")):
            if name not in cls.DESCRIPTOR.fields_by_name:
                raise LiaisonConfigError(f"{where}.{what}: {cls.DESCRIPTOR.full_name} has no field {name!r}")
        if rule.HasField("final_field") and rule.final_field not in ack.DESCRIPTOR.fields_by_name:
            raise LiaisonConfigError(f"{where}.final_field: {rule.ack_type} has no field {rule.final_field!r}")
        out[rule.command_type] = rule
    return out


MAX_UPDATE_FREQ = 100.0  # Hz
MAX_OVERLAY_POINTS = 10_000
WEB = "[goby_moos_py.liaison.protobuf.web]"
#: (where, field, lowest, highest) of every number the server uses as a port, a size or a count.
_RANGES = (
    ("", "http_port", 0, 65535),
    (WEB, "client_queue_updates", 1, 10_000),
    (WEB, "max_clients", 1, 10_000),
    (WEB, "max_scope_rows", 1, 1_000_000),
    (WEB, "command_history", 1, 100_000),
)


def _check_ranges(cfg: LiaisonConfig, extra: WebConfig) -> None:
    for where, name, low, high in _RANGES:
        value = getattr(extra if where else cfg, name)
        if not low <= value <= high:
            raise LiaisonConfigError(f"{where + '.' if where else ''}{name}: {value} is outside [{low}, {high}]")
    if not 1 <= cfg.pb_scope_config.max_history_items <= 100_000:
        raise LiaisonConfigError(f"pb_scope_config.max_history_items: {cfg.pb_scope_config.max_history_items} "
                                 "is outside [1, 100000]")
    if not 1000 <= extra.map.replay_max_samples <= 10_000_000:
        raise LiaisonConfigError(f"{WEB}.map.replay_max_samples: {extra.map.replay_max_samples} is outside "
                                 "[1000, 10000000]")
    if not 2 <= extra.map.trail_points <= 100_000:
        raise LiaisonConfigError(f"{WEB}.map.trail_points: {extra.map.trail_points} is outside [2, 100000]")
    for name in ("waypoint", "loiter_polygon"):
        points = getattr(extra.map, name)
        if len(points) > MAX_OVERLAY_POINTS:
            raise LiaisonConfigError(f"{WEB}.map.{name}: {len(points)} points (at most {MAX_OVERLAY_POINTS})")
        for index, point in enumerate(points):
            if not (math.isfinite(point.x) and math.isfinite(point.y)):
                raise LiaisonConfigError(f"{WEB}.map.{name}[{index}]: x and y must be finite numbers")


MODES = ("POLYGON", "WAYPOINTS")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".gif", ".webp")


def _map_extras(extra: WebConfig) -> tuple[str | None, tuple[float, float] | None, MoosEndpoint | None,
                                           BackgroundImage | None, list[Path]]:
    """The map's optional settings, checked: (initial mode, datum, MOOSDB, background, replay folders)."""
    cfg = extra.map
    where = f"{WEB}.map"
    mode = None
    if cfg.HasField("initial_mode"):
        mode = cfg.initial_mode.strip().upper()
        if mode not in MODES:
            raise LiaisonConfigError(f"{where}.initial_mode: {cfg.initial_mode!r} is not one of {', '.join(MODES)}")
    datum = None
    if cfg.HasField("datum_lat") != cfg.HasField("datum_lon"):
        raise LiaisonConfigError(f"{where}: datum_lat and datum_lon go together")
    if cfg.HasField("datum_lat"):
        if not (-80.0 <= cfg.datum_lat <= 84.0 and -180.0 <= cfg.datum_lon <= 180.0):
            raise LiaisonConfigError(f"{where}: datum {cfg.datum_lat}, {cfg.datum_lon} is outside UTM's range "
                                     "(lat -80..84, lon -180..180)")
        datum = (cfg.datum_lat, cfg.datum_lon)
    moos = None
    if cfg.HasField("moos"):
        if not 1 <= cfg.moos.port <= 65535:
            raise LiaisonConfigError(f"{where}.moos.port: {cfg.moos.port} is outside [1, 65535]")
        moos = MoosEndpoint(cfg.moos.host, cfg.moos.port, cfg.moos.name)
    background = None
    if cfg.HasField("background"):
        bg = cfg.background
        path = Path(bg.image).expanduser()
        if path.suffix.lower() not in IMAGE_SUFFIXES or not path.is_file():
            raise LiaisonConfigError(f"{where}.background.image: {bg.image!r} is not an image file "
                                     f"({', '.join(IMAGE_SUFFIXES)})")
        numbers = (bg.lat_north, bg.lat_south, bg.lon_east, bg.lon_west)
        if not (all(math.isfinite(v) for v in numbers) and -90 <= bg.lat_south < bg.lat_north <= 90
                and -180 <= bg.lon_west < bg.lon_east <= 180):
            raise LiaisonConfigError(f"{where}.background: need lat_south < lat_north and lon_west < lon_east, "
                                     "in degrees")
        background = BackgroundImage(path, *numbers)
    replay_dirs = []
    for index, folder in enumerate(cfg.replay_dir):
        path = Path(folder).expanduser()
        if path.exists() and not path.is_dir():  # one that does not exist yet may be made by the logger
            raise LiaisonConfigError(f"{where}.replay_dir[{index}]: {folder!r} is not a folder")
        replay_dirs.append(path.resolve())
    return mode, datum, moos, background, replay_dirs


def _host_name(host: str, index: int) -> str:
    """An ``allowed_host`` entry as the server compares it: lower case, no port, no brackets."""
    name = host.strip().lower()
    if name.startswith("[") and name.endswith("]"):
        name = name[1:-1]
    if not name or any(c in name for c in "/ @[]") or name.count(":") == 1:
        raise LiaisonConfigError(f"{WEB}.allowed_host[{index}]: {host!r} is not a host name or address "
                                 '(give the name without a port or scheme, e.g. "usv.local")')
    return name


def load_settings(cfg: LiaisonConfig) -> LiaisonSettings:
    """Check the config and derive the settings; LiaisonConfigError names the offending field."""
    for name in ("load_proto_file", "load_proto_dir"):
        if getattr(cfg, name):
            raise LiaisonConfigError(f"{name} is not supported here (no .proto compiler at run time): compile the "
                                     "file with protoc and name the generated module in load_shared_library")
    extra = web_config(cfg)
    import_project_protos()
    load_message_modules([*cfg.load_shared_library, *extra.load_python_module])
    acks = _ack_rules(list(extra.interprocess_ack))
    types = []
    seen = set()
    for index, load in enumerate(cfg.pb_commander_config.load_protobuf):
        where = f"pb_commander_config.load_protobuf[{index}]"
        try:
            cls = find_message_type(load.name)
        except LiaisonConfigError as exc:
            raise LiaisonConfigError(f"{where}.name: {exc}") from None
        if load.name in seen:
            raise LiaisonConfigError(f"{where}.name: {load.name} is listed twice")
        seen.add(load.name)
        types.append(CommandType(load.name, cls, _targets(load, cls, where), acks.get(load.name)))
    scope = cfg.pb_scope_config
    for expression, what in ((scope.group_regex_filter_expression, "group"),
                             (scope.type_regex_filter_expression, "type")):
        try:
            compile_filter(expression, what)
        except ValueError as exc:
            raise LiaisonConfigError(f"pb_scope_config: {exc}") from None
    notify = []
    for index, sub in enumerate(cfg.pb_commander_config.notify_subscribe):
        for expression, what in ((sub.group_regex, "group"), (sub.type_regex, "type")):
            try:
                compile_filter(expression, what)
            except ValueError as exc:
                raise LiaisonConfigError(f"pb_commander_config.notify_subscribe[{index}]: {exc}") from None
        notify.append((sub.group_regex, sub.type_regex))
    if not 0 < cfg.update_freq <= MAX_UPDATE_FREQ:
        raise LiaisonConfigError(f"update_freq must be in (0, {MAX_UPDATE_FREQ:g}] Hz, not {cfg.update_freq:g}")
    _check_ranges(cfg, extra)
    allowed_hosts = [_host_name(h, index) for index, h in enumerate(extra.allowed_host)]
    initial_mode, datum, moos, background, replay_dirs = _map_extras(extra)
    platform = cfg.interprocess.platform
    return LiaisonSettings(
        title=f"goby liaison: {platform}",
        http_address=cfg.http_address,
        http_port=cfg.http_port,
        update_freq=cfg.update_freq,
        start_paused=cfg.start_paused,
        views={"scope": cfg.add_scope_tab, "commander": cfg.add_commander_tab, "home": cfg.add_home_tab,
               "map": True},
        group_filter=scope.group_regex_filter_expression,
        type_filter=scope.type_regex_filter_expression,
        max_history=scope.max_history_items,
        max_message_size=scope.max_message_size_bytes,
        history_groups=[h.group for h in scope.history],
        command_types=types,
        notify=notify,
        waypoints=[(p.x, p.y) for p in extra.map.waypoint],
        polygon=[(p.x, p.y) for p in extra.map.loiter_polygon],
        center_activate=extra.map.center_activate,
        trail_points=extra.map.trail_points,
        client_queue=extra.client_queue_updates,
        max_clients=extra.max_clients,
        max_rows=extra.max_scope_rows,
        command_history=extra.command_history,
        allowed_hosts=allowed_hosts,
        initial_mode=initial_mode,
        datum=datum,
        moos=moos,
        background=background,
        replay_dirs=replay_dirs,
        replay_max_samples=extra.map.replay_max_samples,
    )
