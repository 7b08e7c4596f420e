"""``python -m launch.trail.config PLATFORM APP``: print one app's configuration (the course's ``<platform>.pb.cfg.py``).

PLATFORM is ``topside``, ``usv`` or ``auv``; the course's ``goby3_course_n_auvs`` (usv, auv) and
``goby3_course_auv_index`` (auv) say which vehicle, ``TRAIL_*`` variables the rest (``launch.trail.settings``).
Goby-style apps get protobuf text format, read through bash process substitution (``app <(...)``);
``frontseat_sim`` prints the simulator's port; ``moos`` and ``bhv`` write ``<run_dir>/<platform>.moos`` /
``.bhv`` and print the path, because MOOS applications read their file more than once and cannot use process
substitution (``launch.trail.moos_gen`` writes both too and removes them on exit, as the course's
``moos_gen.sh``); ``helm_command`` prints the command line of the USV's chosen helm. The course's app names
(``gobyd``, ``goby_frontseat_interface_basic_simulator``, ``goby3_course_usv_manager``...) are accepted too.
An unknown app prints ``App: ... not defined``; a missing variable the course's INVALID CONFIGURATION banner.
"""

from __future__ import annotations

import os
import shlex
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

from google.protobuf import text_format

from launch.config import (
    SHARED_TEMPLATES,
    config_main,
    find_generator,
    make_dirs,
    render,
    text_format_string,
)
from launch.errors import MissionConfigError
from launch.record import load_shared_library_lines
from launch.trail.settings import (
    MULTICAST_ADDRESS,
    REPO_ROOT,
    SUBNET_MASK,
    TRAIL_DIR,
    TrailSettings,
    Vehicle,
    acomms_mac_slots,
    auv_modem_ids,
    satellite_mac_slots,
    vehicle_from_env,
)
from launch.usv.settings import USV_DIR
from util.process import WaitTimeout, wait_until

TEMPLATES = TRAIL_DIR / "templates"
# goby-coroner and usv-health-monitor: the USV mission's templates, one list of expected names for both missions
USV_TEMPLATES = USV_DIR / "templates"

USV_BHV = REPO_ROOT / "behaviors" / "usv.bhv"
AUV_BHV_TEMPLATE = REPO_ROOT / "behaviors" / "auv.bhv.in"

# The course's app names -> ours.
ALIASES = {
    "goby-broker": "gobyd",
    "broker": "gobyd",
    "goby_frontseat_interface_basic_simulator": "frontseat_interface",
    "goby_liaison": "liaison",
    "goby_moos_gateway": "moos_gateway",
    "goby3_course_usv_manager": "usv_manager",
    "goby3_course_auv_manager": "auv_manager",
    "goby3_course_topside_manager": "topside_manager",
    "goby3_course_helm": "helm",
    "goby3_course_usv_health_monitor": "usv_health_monitor",
    "goby_opencpn_interface": "opencpn_interface",
}


def _values(settings: TrailSettings, vehicle: Vehicle, app: str) -> dict[str, object]:
    values: dict[str, object] = {
        "app": app,
        "name": vehicle.name,
        "kind": vehicle.kind,
        "warp": settings.warp,
        "lat_origin": repr(settings.lat_origin),
        "lon_origin": repr(settings.lon_origin),
        "platform": vehicle.name,
        "socket_name": vehicle.ipc_base(settings),
        "moos_host": settings.moos_address,
        "moos_port": vehicle.moos_port(settings),
        "sim_port": vehicle.sim_port(settings),
        "vehicle_id": vehicle.vehicle_id,
        "vehicle_type": vehicle.kind.upper(),
        "timeout": max(10, 3 * settings.warp),  # as the USV mission: three real seconds at least
        "liaison_address": text_format_string(settings.liaison_address),
        "liaison_port": vehicle.liaison_port(settings),
        "east_duration": settings.east_duration,
        "south_duration": settings.south_duration,
        "ais_address": text_format_string(settings.ais_address),
        "ais_port": settings.ais_port,
    }
    values["app_block"] = render(SHARED_TEMPLATES / "_app.pb.cfg.in", values)
    values["interprocess_block"] = (render(SHARED_TEMPLATES / "_interprocess.pb.cfg.in", values)
                                    if not settings.broker_address else _tcp_interprocess(settings, vehicle))
    return values


def _tcp_interprocess(settings: TrailSettings, vehicle: Vehicle) -> str:
    """Goby's interprocess TCP transport (a vehicle of two computers, docs/hosts.md): the broker binds
    ``ipv4_address:tcp_port`` and every app of the vehicle, on either computer, connects there."""
    return f"""interprocess {{
  platform: "{vehicle.name}"
  transport: TCP
  ipv4_address: "{settings.broker_address}"  # TRAIL_BROKER_ADDRESS
  tcp_port: {settings.broker_port}  # TRAIL_BROKER_PORT
  manager_timeout_seconds: 30
}}"""


def _pb(template: str, app: str, directory: Path = TEMPLATES) -> Callable[[TrailSettings, Vehicle], str]:
    def generate(settings: TrailSettings, vehicle: Vehicle) -> str:
        path = directory / template
        return render(path if path.is_file() else SHARED_TEMPLATES / template, _values(settings, vehicle, app))

    return generate


# -- gobyd: the intervehicle links ------------------------------------------------------------------------


def link_block(settings: TrailSettings, vehicle: Vehicle, link: str) -> str:
    """One ``link {}`` (goby.middleware.intervehicle.protobuf.PortalConfig.link), as _link_<link>.pb.cfg.in."""
    if link == "satellite":
        modem_id, port, slots = vehicle.satellite_modem_id, settings.satellite_port, satellite_mac_slots()
    else:
        modem_id, port, slots = vehicle.acomms_modem_id, settings.acomms_port, acomms_mac_slots(vehicle.n_auvs)
    slot_lines = "\n".join(
        f"      slot {{ src: {src} slot_seconds: {seconds} max_frame_bytes: {size} }}" for src, seconds, size in slots
    )
    return f"""  link {{  # {link}
    modem_id: {modem_id}
    subnet_mask: {SUBNET_MASK}  # 0xFF00
    driver {{
      driver_type: DRIVER_UDP_MULTICAST
      [goby.acomms.udp_multicast.protobuf.config] {{
        listen_address: "{settings.link_address}"  # TRAIL_LINK_ADDRESS (docs/launch.md)
        multicast_address: "{MULTICAST_ADDRESS}"
        multicast_port: {port}
        max_frame_size: 1400
      }}{_peers_block(settings)}{_channel_block(settings, link)}
    }}
    mac {{
      type: MAC_FIXED_DECENTRALIZED
{slot_lines}
    }}
  }}"""


def _peers_block(settings: TrailSettings) -> str:
    """Our ``udp_peers`` extension: the only sources the link accepts (TRAIL_LINK_PEERS), when given."""
    peers = " ".join(f'peer_address: "{p}"' for p in settings.peer_networks())
    if not peers:
        return ""
    return ("\n      # datagrams from other sources are dropped (TRAIL_LINK_PEERS, docs/hosts.md)"
            f"\n      [goby_moos_py.acomms.protobuf.udp_peers] {{ {peers} }}")


def _moosdb_flags(settings: TrailSettings, vehicle: Vehicle) -> str:
    """Our moos-db's ``--moos_address`` (TRAIL_MOOS_ADDRESS); nothing for the real MOOSDB, which binds every
    interface of its host."""
    return "" if os.path.basename(settings.moosdb) == "MOOSDB" else f"--moos_address={settings.moos_address}"


def _channel_block(settings: TrailSettings, link: str) -> str:
    """The driver's simulated channel (our ``channel_model`` extension), when the settings impair this link."""
    model = settings.channel_model(link)
    if model is None:
        return ""
    text = text_format.MessageToString(model, as_one_line=True)
    return (f"\n      # simulated channel on receive (TRAIL_{link.upper()}_CHANNEL, docs/intervehicle.md)"
            f"\n      [goby_moos_py.acomms.protobuf.channel_model] {{ {text} }}")


def broker_hosts_intervehicle() -> bool:
    """True once goby-broker's config (GobyDaemonConfig) has gobyd's ``intervehicle`` field."""
    from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig

    return "intervehicle" in GobyDaemonConfig.DESCRIPTOR.fields_by_name


def intervehicle_block(settings: TrailSettings, vehicle: Vehicle) -> str:
    links = "\n".join(link_block(settings, vehicle, link) for link in vehicle.links)
    block = f"intervehicle {{\n{links}\n}}"
    if not broker_hosts_intervehicle():
        # Kept visible in the generated text, so the missing piece is obvious.
        return "# this goby-broker has no intervehicle layer yet; the links gobyd would run:\n" + "\n".join(
            f"# {line}" for line in block.splitlines()
        )
    return block


def _gobyd(settings: TrailSettings, vehicle: Vehicle) -> str:
    values = _values(settings, vehicle, "goby-broker")
    values["intervehicle_block"] = intervehicle_block(settings, vehicle)
    return render(TEMPLATES / "gobyd.pb.cfg.in", values)


# -- managers, helm, liaison ------------------------------------------------------------------------------


def _manager(app: str, kind: str) -> Callable[[TrailSettings, Vehicle], str]:
    def generate(settings: TrailSettings, vehicle: Vehicle) -> str:
        if vehicle.kind != kind:
            raise MissionConfigError(f"App: {app} is not defined for platform {vehicle.kind}")
        values = _values(settings, vehicle, app)
        usv = Vehicle("usv", vehicle.n_auvs)
        if kind == "topside":
            extra = f"usv_modem_id: {usv.satellite_modem_id}"
        elif kind == "usv":
            extra = "\n".join(f"auv_modem_id: {m}" for m in auv_modem_ids(vehicle.n_auvs))
        else:
            extra = f"usv_modem_id: {usv.acomms_modem_id}"
        values["manager_extra"] = extra
        return render(TEMPLATES / "manager.pb.cfg.in", values)

    return generate


def _liaison(settings: TrailSettings, vehicle: Vehicle) -> str:
    """goby-liaison: the topside's Commander sends USVCommand on intervehicle usv_command/0, as the course's."""
    values = _values(settings, vehicle, "goby-liaison")
    commander = ""
    if vehicle.kind == "topside":
        commander = """pb_commander_config {
  load_protobuf {
    name: "goby3_course.dccl.USVCommand"
    publish_to { group: "goby3_course::usv_command" group_numeric: 0 layer: LAYER_INTERVEHICLE }
  }
}"""
    values["commander_block"] = commander
    return render(TEMPLATES / "liaison.pb.cfg.in", values)


def _liaison_web(settings: TrailSettings, vehicle: Vehicle) -> str:
    """goby-liaison's own map settings (``--web``): the datum for the cursor's lat/lon, this run's logs for replay,
    and on a vehicle its MOOSDB, so the map draws the helm's own VIEW_* and DEPLOY_STATE. The topside has no
    MOOSDB: it starts from the USV's initial DEPLOY_STATE (usv.bhv's POLYGON) and models what it commands."""
    lines = [f"datum_lat: {settings.lat_origin!r}", f"datum_lon: {settings.lon_origin!r}",
             f"replay_dir: {text_format_string(str(settings.run_dir / 'logs'))}"]
    if vehicle.kind in ("topside", "usv") and settings.usv_helm == "ivp":
        lines += ["center_activate: true", 'initial_mode: "POLYGON"']
    if vehicle.kind != "topside":
        lines.append(f'moos {{ host: {text_format_string(settings.moos_address)} port: {vehicle.moos_port(settings)} }}')
    return "map {\n  " + "\n  ".join(lines) + "\n}\n"


def _goby_logger(settings: TrailSettings, vehicle: Vehicle) -> str:
    """goby-logger (the course's post-homework-4 goby_logger): the platform's broker into
    ``<run_dir>/logs/<platform>/<platform>_<time>.goby``, next to the moos-logger's .alog directory."""
    values = _values(settings, vehicle, "goby-logger")
    values["data_log_dir"] = vehicle.log_dir(settings)
    # Goby3's goby_logger dlopen()s each load_shared_library and exits on a Python module name
    values["load_shared_library"] = ("" if os.path.basename(settings.goby_logger) == "goby_logger"
                                     else load_shared_library_lines())
    return render(SHARED_TEMPLATES / "goby_logger.pb.cfg.in", values)


def _vehicle_only(
    kinds: tuple[str, ...], app: str, generate: Callable[[TrailSettings, Vehicle], str]
) -> Callable[[TrailSettings, Vehicle], str]:
    def checked(settings: TrailSettings, vehicle: Vehicle) -> str:
        if vehicle.kind not in kinds:
            raise MissionConfigError(f"App: {app} is not defined for platform {vehicle.kind}")
        return generate(settings, vehicle)

    return checked


# -- MOOS files --------------------------------------------------------------------------------------------


def bhv_text(settings: TrailSettings, vehicle: Vehicle) -> str:
    """usv.bhv as is; auv.bhv.in with this AUV's trail angle and depth."""
    if vehicle.kind == "usv":
        return USV_BHV.read_text()
    return render(AUV_BHV_TEMPLATE, {"trail_angle": f"{vehicle.trail_angle:g}",
                                     "deploy_depth": f"{vehicle.deploy_depth:g}"})


def moos_text(settings: TrailSettings, vehicle: Vehicle) -> str:
    values = _values(settings, vehicle, "moos")
    values["community"] = vehicle.community
    values["data_log_dir"] = vehicle.log_dir(settings)
    values["bhv_file"] = vehicle.bhv_file(settings)
    values["share_block"] = _share_block(settings, vehicle)
    domains = ["course:0:359:360", "speed:0:2:41"] if vehicle.kind == "usv" else \
        ["course:0:359:360", "speed:0:4:41", "depth:0:200:201"]
    values["domains"] = "\n".join(f"  domain = {d}" for d in domains)
    values["platform_type"], values["platform_color"], values["platform_length"] = (
        ("usv", "green", 4) if vehicle.kind == "usv" else ("auv", "yellow", 2))
    return render(TEMPLATES / "trail.moos.in", values)


def _write_atomic(path: Path, text: str) -> Path:
    """Several launch lines may generate the same file at once: write a temporary file and rename it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}-", suffix=".tmp")
    with os.fdopen(fd, "w") as out:
        out.write(text)
    os.replace(tmp, path)
    return path


def _share_block(settings: TrailSettings, vehicle: Vehicle) -> str:
    """moos-share's ``ProcessConfig = pShare`` (the course's pShare lines): each AUV sends its NODE_REPORT_LOCAL as
    NODE_REPORT to the USV's input (``share_port_base`` + the USV's id, on ``usv_address``), which the USV binds.
    At most ten a real second per AUV (moos-share's ``frequency`` is real time): node-reporter's rate at warp 1, as
    the course shares every one; under warp node-reporter posts ten a sim second, hundreds a real second, and the
    USV's MOOSDB would take them all for a display.
    """
    usv = Vehicle("usv", vehicle.n_auvs)
    route = f"{settings.usv_address}:{usv.share_port(settings)}"
    if vehicle.kind == "usv":
        line = f"Input = route = {settings.usv_address}:{vehicle.share_port(settings)}"
    else:
        line = f"Output = src_name = NODE_REPORT_LOCAL, dest_name = NODE_REPORT, route = {route}, frequency = 10"
    return f"""//------------------------------------------------------------
// moos-share (pShare's role, docs/moos_share.md): the AUVs' NODE_REPORT_LOCAL reach the USV's MOOSDB as NODE_REPORT
ProcessConfig = pShare
{{
  AppTick = 4
  CommsTick = 4
  {line}
}}"""


def write_moos_files(settings: TrailSettings, vehicle: Vehicle) -> tuple[Path, Path]:
    """Write ``<platform>.moos`` and ``<platform>.bhv`` into the run directory; return both paths."""
    if vehicle.kind == "topside":
        raise MissionConfigError("App: moos is not defined for platform topside (it runs no MOOS)")
    bhv = _write_atomic(vehicle.bhv_file(settings), bhv_text(settings, vehicle))
    moos = _write_atomic(vehicle.moos_file(settings), moos_text(settings, vehicle))
    return moos, bhv


MOOSDB_WAIT_S = 60.0  # a platform's processes all start at once; on a loaded machine the MOOSDB takes seconds


def _moos_after_db(settings: TrailSettings, vehicle: Vehicle) -> str:
    """``moos``, printed once the vehicle's MOOSDB listens. The real pHelmIvP posts its behaviour file's
    ``initialize`` variables once, at start-up, whether or not it is connected: started before its MOOSDB (whose
    line runs two config generators to the helm's one) it loses them and stays in PARK."""
    moos, _ = write_moos_files(settings, vehicle)
    port = vehicle.moos_port(settings)
    try:
        wait_until(lambda: _listening(port), MOOSDB_WAIT_S, f"the MOOSDB on port {port}", interval=0.1)
    except WaitTimeout as exc:
        raise MissionConfigError(str(exc)) from None
    return str(moos)


def _listening(port: int) -> bool:
    """True when a TCP socket of this network namespace listens on ``port`` (``/proc/net/tcp``). No connection is
    made: the real MOOSDB logs a client that never shakes hands as a protocol error."""
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            rows = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for row in rows:
            fields = row.split()  # sl local_address rem_address st ...; st 0A is LISTEN
            if len(fields) > 3 and fields[3] == "0A" and int(fields[1].rsplit(":", 1)[1], 16) == port:
                return True
    return False


def _helm_command(settings: TrailSettings, vehicle: Vehicle) -> str:
    """The USV helm's command line: the MOOS helm on usv.moos (ivp), or goby-helm-example (goby)."""
    if settings.usv_helm == "goby":
        path = _write_atomic(settings.run_dir / f"{vehicle.name}_helm.pb.cfg", _pb("helm.pb.cfg.in",
                                                                                     "goby-helm-example")(settings, vehicle))
        return f"goby-helm-example {shlex.quote(str(path))}"
    moos, _ = write_moos_files(settings, vehicle)
    return f"{shlex.quote(settings.helm)} {shlex.quote(str(moos))}"


GENERATORS: dict[str, Callable[[TrailSettings, Vehicle], str]] = {
    "gobyd": _gobyd,
    "frontseat_sim": _vehicle_only(("usv", "auv"), "frontseat_sim", lambda s, v: str(v.sim_port(s))),
    "frontseat_interface": _vehicle_only(("usv", "auv"), "frontseat_interface",
                                         _pb("frontseat_interface.pb.cfg.in", "frontseat-interface")),
    "frontseat_tuning": _vehicle_only(("usv", "auv"), "frontseat_tuning",
                                      _pb("frontseat_tuning.pb.cfg.in", "frontseat-interface")),
    "moos_gateway": _vehicle_only(("usv", "auv"), "moos_gateway", _pb("moos_gateway.pb.cfg.in", "moos-gateway")),
    "topside_manager": _manager("topside-manager", "topside"),
    "usv_manager": _manager("usv-manager", "usv"),
    "auv_manager": _manager("auv-manager", "auv"),
    "liaison": _liaison,
    "liaison_web": _liaison_web,  # given on goby-liaison's command line (--web), like the USV mission's
    "goby_coroner": _vehicle_only(("usv",), "goby_coroner",
                                  _pb("goby_coroner.pb.cfg.in", "goby-coroner", USV_TEMPLATES)),
    "usv_health_monitor": _vehicle_only(("usv",), "usv_health_monitor",
                                        _pb("usv_health_monitor.pb.cfg.in", "usv-health-monitor", USV_TEMPLATES)),
    "opencpn_interface": _vehicle_only(("topside",), "opencpn_interface",
                                       _pb("goby_opencpn_interface.pb.cfg.in", "goby-opencpn-interface")),
    "goby_logger": _goby_logger,
    "helm": _vehicle_only(("usv",), "helm", _pb("helm.pb.cfg.in", "goby-helm-example")),
    "helm_command": _vehicle_only(("usv",), "helm_command", _helm_command),
    "commander": _vehicle_only(("topside",), "commander", _pb("commander.pb.cfg.in", "trail-commander")),
    "moosdb_flags": _vehicle_only(("usv", "auv"), "moosdb_flags", _moosdb_flags),
    "moos": lambda s, v: str(write_moos_files(s, v)[0]),
    "moos_after_db": _moos_after_db,
    "bhv": lambda s, v: str(write_moos_files(s, v)[1]),
}


def generate(platform: str, app: str, settings: TrailSettings, vehicle: Vehicle | None = None) -> str:
    """One app's configuration text; MissionConfigError for an unknown app, a bad setting or a missing variable."""
    generator = find_generator(GENERATORS, ALIASES.get(app, app))
    vehicle = vehicle or vehicle_from_env(platform)
    make_dirs(settings.run_dir, settings.sockets, vehicle.log_dir(settings))
    return generator(settings, vehicle)


def main(argv: list[str] | None = None) -> int:
    return config_main(argv, f"python -m launch.trail.config PLATFORM APP   (PLATFORM topside|usv|auv; APP one of "
                       f"{', '.join(sorted(GENERATORS))})", 2,
                       lambda platform, app: generate(platform, app, TrailSettings.from_env()))


if __name__ == "__main__":
    sys.exit(main())
