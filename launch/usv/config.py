"""``python -m launch.usv.config APP``: print one USV application's configuration (the course's usv.pb.cfg.py).

Goby-style apps get protobuf text format (read through bash process substitution, ``app <(...)``);
``frontseat_sim`` prints the simulator's port; ``moos`` writes the .moos mission file into the run
directory and prints its path, because MOOS applications read their file more than once and cannot
use process substitution. All values come from ``UsvSettings.from_env()``.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

from launch.config import SHARED_TEMPLATES, config_main, find_generator, make_dirs, render, text_format_string
from launch.errors import MissionConfigError
from launch.record import load_shared_library_lines
from launch.usv.analysis import bhv_loiter_polygon, bhv_waypoints
from launch.usv.settings import USV_DIR, UsvSettings
from translators.usv.satellite import TOPSIDE_MODEM_ID, USV_MODEM_ID

TEMPLATES = USV_DIR / "templates"


def _values(settings: UsvSettings, app: str) -> dict[str, object]:
    values: dict[str, object] = {
        "app": app,
        "warp": settings.warp,
        "lat_origin": repr(settings.lat_origin),
        "lon_origin": repr(settings.lon_origin),
        "platform": settings.platform,
        "socket_name": settings.ipc_base,
        "moos_host": "127.0.0.1",
        "moos_port": settings.moos_port,
        "sim_port": settings.sim_port,
        "community": settings.community,
        "vehicle_id": settings.vehicle_id,
        "bhv_file": settings.bhv_file,
        "timeout": settings.liveness_timeout,
        "liaison_address": text_format_string(settings.liaison_address),
        "liaison_port": settings.liaison_port,
        "vehicle_type": "USV",
    }
    values["app_block"] = render(SHARED_TEMPLATES / "_app.pb.cfg.in", values)
    values["interprocess_block"] = render(SHARED_TEMPLATES / "_interprocess.pb.cfg.in", values)
    values["intervehicle_block"] = _satellite_block(settings, USV_MODEM_ID)
    return values


def _topside_values(settings: UsvSettings, app: str) -> dict[str, object]:
    """The values of an app on the topside's own broker (the shore), whose satellite modem is 1."""
    values = _values(settings, app)
    values["platform"] = settings.topside_platform
    values["socket_name"] = settings.topside_ipc_base
    values["interprocess_block"] = render(SHARED_TEMPLATES / "_interprocess.pb.cfg.in", values)
    values["intervehicle_block"] = _satellite_block(settings, TOPSIDE_MODEM_ID)
    return values


def _satellite_block(settings: UsvSettings, modem_id: int) -> str:
    """The broker's intervehicle block: the course's satellite link (topside 1, USV 2; 5 s / 64 B slots)."""
    return render(TEMPLATES / "_satellite_link.pb.cfg.in", {"modem_id": modem_id, "sat_port": settings.sat_port})


def _pb(template: str, app: str) -> Callable[[UsvSettings], str]:
    def generate(settings: UsvSettings) -> str:
        path = TEMPLATES / template
        return render(path if path.is_file() else SHARED_TEMPLATES / template, _values(settings, app))

    return generate


def _topside(template: str, app: str) -> Callable[[UsvSettings], str]:
    def generate(settings: UsvSettings) -> str:
        return render(TEMPLATES / template, _topside_values(settings, app))

    return generate


def _vehicle_interprocess(settings: UsvSettings) -> str:
    """The USV broker's interprocess block on one line (the shore watches the vehicle's state there)."""
    return " ".join(render(SHARED_TEMPLATES / "_interprocess.pb.cfg.in", _values(settings, "usv-shore"))
                    .replace("interprocess {", "").replace("}", "").split())


def _goby_logger(topside: bool) -> Callable[[UsvSettings], str]:
    """goby-logger on the USV's broker (or the topside's): ``<run_dir>/logs/<platform>/<platform>_<time>.goby``."""

    def generate(settings: UsvSettings) -> str:
        values = _topside_values(settings, "goby-logger") if topside else _values(settings, "goby-logger")
        values["data_log_dir"] = data_log_dir(settings, str(values["platform"]))
        values["load_shared_library"] = load_shared_library_lines()
        return render(SHARED_TEMPLATES / "goby_logger.pb.cfg.in", values)

    return generate


def data_log_dir(settings: UsvSettings, platform: str) -> Path:
    """Where a platform's goby-logger and moos-logger write: ``<run_dir>/logs/<platform>``."""
    return settings.log_dir / platform


def _topside_manager(settings: UsvSettings) -> str:
    """topside-manager on the topside's broker: the USV's nav and health from its satellite modem."""
    values = _topside_values(settings, "topside-manager")
    values["usv_modem_id"] = USV_MODEM_ID
    return render(TEMPLATES / "topside_manager.pb.cfg.in", values)


def _liaison(settings: UsvSettings) -> str:
    """goby-liaison's config: the course's liaison.pb.cfg.in with our commander target (Goby3's fields only)."""
    return render(TEMPLATES / "liaison.pb.cfg.in", _values(settings, "goby-liaison"))


def _topside_liaison(settings: UsvSettings) -> str:
    """The topside's goby-liaison (the course's topside page): its Commander sends USVCommand on intervehicle
    ``goby3_course::usv_command`` group 0 over the satellite link, acked by the USV's modem."""
    values = _topside_values(settings, "goby-liaison")
    values["liaison_port"] = settings.topside_liaison_port
    return render(TEMPLATES / "topside_liaison.pb.cfg.in", values)


def _liaison_web(settings: UsvSettings) -> str:
    """goby-liaison's own settings (``--web``): the map of usv.bhv and the command acknowledgements."""
    values = _values(settings, "goby-liaison")
    points = "\n    ".join(f"waypoint {{ x: {x:g} y: {y:g} }}" for x, y in bhv_waypoints(settings.bhv_file))
    polygon = bhv_loiter_polygon(settings.bhv_file)
    if polygon is not None:
        points += "\n    " + "\n    ".join(f"loiter_polygon {{ x: {x:.1f} y: {y:.1f} }}" for x, y in polygon.vertices)
    values["map_points"] = points
    values["replay_dir"] = text_format_string(str(settings.run_dir / "logs"))  # the map replays this run's logs
    return render(TEMPLATES / "liaison_web.pb.cfg.in", values)


def moos_file_text(settings: UsvSettings) -> str:
    """The .moos mission file's text (globals shared with the Goby side, the helm's ProcessConfig)."""
    values = _values(settings, "moos")
    values["data_log_dir"] = data_log_dir(settings, settings.platform)
    return render(TEMPLATES / "usv.moos.in", values)


def write_moos_file(settings: UsvSettings) -> Path:
    """Write the .moos file atomically (several launch lines may generate it at once); return its path."""
    path = settings.moos_file
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".moos-", suffix=".tmp")
    with os.fdopen(fd, "w") as out:
        out.write(moos_file_text(settings))
    os.replace(tmp, path)
    return path


def _moos(settings: UsvSettings) -> str:
    if not settings.bhv_file.is_file():
        raise MissionConfigError(f"behaviour file {settings.bhv_file} does not exist (USV_BHV_FILE)")
    return str(write_moos_file(settings))


GENERATORS: dict[str, Callable[[UsvSettings], str]] = {
    "broker": _pb("broker.pb.cfg.in", "goby-broker"),
    "frontseat_sim": lambda s: str(s.sim_port),
    "frontseat_interface": _pb("frontseat_interface.pb.cfg.in", "frontseat-interface"),
    # our driver's own settings, given on frontseat-interface's command line (--frontseat_cfg), so that the
    # config file holds Goby3's fields only and the real goby_frontseat_interface accepts it
    "frontseat_tuning": _pb("frontseat_tuning.pb.cfg.in", "frontseat-interface"),
    "moos_gateway": _pb("moos_gateway.pb.cfg.in", "moos-gateway"),
    "usv_manager": _pb("usv_manager.pb.cfg.in", "usv-manager"),
    "goby_coroner": _pb("goby_coroner.pb.cfg.in", "goby-coroner"),
    "usv_health_monitor": _pb("usv_health_monitor.pb.cfg.in", "usv-health-monitor"),
    "goby_logger": _goby_logger(topside=False),
    "topside_goby_logger": _goby_logger(topside=True),
    "topside_manager": _topside_manager,
    "topside_broker": _topside("broker.pb.cfg.in", "goby-broker"),
    "shore": _topside("shore.pb.cfg.in", "usv-shore"),
    "usv_command": _topside("shore.pb.cfg.in", "usv-command"),  # for sending commands by hand
    "vehicle_interprocess": _vehicle_interprocess,
    "liaison": _liaison,
    "topside_liaison": _topside_liaison,
    "liaison_web": _liaison_web,  # given on goby-liaison's command line (--web), like frontseat_tuning
    "moos": _moos,
}


def generate(app: str, settings: UsvSettings) -> str:
    """One app's configuration text; MissionConfigError for an unknown app or a bad setting."""
    generator = find_generator(GENERATORS, app)
    # The run directory holds the broker's sockets and the .moos file: make sure it exists whichever app comes first.
    make_dirs(settings.run_dir, Path(settings.ipc_base).parent, Path(settings.topside_ipc_base).parent,
              data_log_dir(settings, settings.platform), data_log_dir(settings, settings.topside_platform))
    return generator(settings)


def main(argv: list[str] | None = None) -> int:
    return config_main(argv, f"python -m launch.usv.config APP   (APP one of {', '.join(sorted(GENERATORS))})", 1,
                       lambda app: generate(app, UsvSettings.from_env()))


if __name__ == "__main__":
    sys.exit(main())
