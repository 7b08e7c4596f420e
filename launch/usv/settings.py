"""The USV mission's settings, in one place: every generated config reads them from here.

Settings travel to the launch lines as ``USV_*`` environment variables (see ``to_env``/``from_env``),
the way the course passes ``goby3_course_n_auvs``; the config generator run by each line rebuilds
the same ``UsvSettings`` from them. Defaults follow the course: vehicle id 1, MOOS port 9000+id,
simulator port 55000+id, the Kauai origin, platform ``usv``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

from launch.config import EnvSettings, check_warp_and_origin, env_variables
from launch.errors import MissionConfigError

REPO_ROOT = Path(__file__).resolve().parents[2]
USV_DIR = Path(__file__).resolve().parent
KAUAI_ORIGIN = (21.590491, -159.534166)
BUZZARDS_BAY_ORIGIN = (41.592344, -70.711260)

# The shore script's default plan: (sim seconds after the vehicle is under helm command, command).
DEFAULT_SCHEDULE = "0:polygon:6:200,500:waypoints,800:polygon:8:400"

_ENV = env_variables("USV_", (
    "run_dir", "warp", "lat_origin", "lon_origin", "platform", "community", "vehicle_id", "moos_port", "sim_port",
    "moosdb", "helm", "bhv_file", "schedule", "socket_name", "liaison_address", "liaison_port",
    "topside_liaison_port", "sat_port"), schedule="USV_SHORE_SCHEDULE")


@dataclass(frozen=True)
class UsvSettings(EnvSettings):
    """Everything two processes must agree on: time warp, origin, ports, names, file places."""

    ENV: ClassVar[Mapping[str, str]] = _ENV

    run_dir: Path = Path("/tmp/usv_mission")
    warp: int = 20
    lat_origin: float = KAUAI_ORIGIN[0]
    lon_origin: float = KAUAI_ORIGIN[1]
    platform: str = "usv"
    community: str = "usv"
    vehicle_id: int = 1
    moos_port: int = 9001
    sim_port: int = 55001
    moosdb: str = "moos-db"
    helm: str = "ivp-helm"
    bhv_file: Path = REPO_ROOT / "behaviors" / "usv.bhv"
    schedule: str = DEFAULT_SCHEDULE
    socket_name: str = ""
    liaison_address: str = "127.0.0.1"  # goby-liaison's http_address: loopback unless asked (it has no login)
    liaison_port: int = 50001  # the course's liaison port: 50000 + vehicle id
    topside_liaison_port: int = 0  # the topside's page (Commander); the demo asks for the course's 50000; 0: any free
    sat_port: int = 54500  # the satellite link's UDP multicast port (the course's; 239.142.0.2)
    topside_platform: str = "topside"  # the shore's own broker (satellite modem 1)

    def __post_init__(self) -> None:
        check_warp_and_origin(self.warp, self.lat_origin, self.lon_origin)
        for port_name in ("moos_port", "sim_port", "liaison_port", "sat_port", "topside_liaison_port"):
            port = getattr(self, port_name)
            if not 0 < port < 65536 and not (port == 0 and port_name == "topside_liaison_port"):
                raise MissionConfigError(f"{port_name} {port} is not a TCP port")

    @property
    def ipc_base(self) -> str:
        """The broker's IPC socket base (``<base>.manager``, ``.xpub``, ``.xsub``), short enough for AF_UNIX."""
        return self.socket_name or str(self.run_dir / f"goby_{self.platform}")

    @property
    def topside_ipc_base(self) -> str:
        """The topside broker's IPC socket base, next to the USV's."""
        return str(Path(self.ipc_base).with_name(f"goby_{self.topside_platform}"))

    @property
    def liveness_timeout(self) -> int:
        """Sim seconds without a helm report or frontseat data before the interface calls it an error.

        The course uses 10; at warp 20 that is half a real second, less than a Python process needs to start
        or than a busy machine may delay one message, so it grows with the warp (three real seconds).
        """
        return max(10, 3 * self.warp)

    @property
    def moos_file(self) -> Path:
        return self.run_dir / f"{self.platform}.moos"

    @property
    def log_dir(self) -> Path:
        return self.run_dir / "logs"

