"""Run the trail mission (or one platform of it) from Python: its launch lines, the stop, and its logs read.

Used by the demo (``launch.trail.demo``), the mission test and the fleet benchmark, so all run exactly what
``./all.launch`` runs: the same nested ``goby-launch`` lines (``generate_all_launch.all_launch_text``) with the
same generated configs. Every platform runs goby-logger (and, with a MOOSDB, moos-logger) into its log directory
(``<run_dir>/logs/<platform>``); the mission reads those logs as they grow (``PlatformLogs``: the wait for
command, the progress lines) and, after the stop, whole (``TrailResult.records``). All times are sim seconds on
the logs' time base (``launch.recorder``), so vehicles and commands line up.
"""

from __future__ import annotations

import dataclasses
import logging
import random
import socket
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from gateway.goby.portal.endpoints import ipc_manager_path
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from launch.apps.goby_launch import LAUNCH_DIR_VAR, LOG_DIR_VAR, PLATFORM_VAR
from launch.errors import LaunchError, ProcessDiedError
from launch.hosts import Host, HostNetwork
from launch.launchfile import LaunchEntry, parse_file, parse_lines
from launch.mission import ProcessOutcome, outcomes, scan_log_files
from launch.portal_thread import BackgroundPortalThread
from launch.process_group import ProcessGroup, child_environment
from launch.record import MissionRecord, shifted, until
from launch.recorder import PlatformLogs, SimClock, read_platform
from launch.trail.generate_all_launch import all_launch_text
from launch.trail.settings import AUV_INDEX_VAR, N_AUVS_VAR, TRAIL_DIR, TrailSettings, Vehicle

log = logging.getLogger(__name__)

COMMAND_STATE = "INTERFACE_COMMAND"


def fleet(n_auvs: int) -> list[Vehicle]:
    """Every platform of an all.launch run, in launch order."""
    return [Vehicle("topside", n_auvs), Vehicle("usv", n_auvs), *(Vehicle("auv", n_auvs, i) for i in range(n_auvs))]


def all_launch_entries(n_auvs: int) -> list[LaunchEntry]:
    return parse_lines(all_launch_text(n_auvs, launch_dir=str(TRAIL_DIR)).splitlines(), source="all.launch").entries


def platform_entries(vehicle: Vehicle) -> list[LaunchEntry]:
    """One platform's launch file as its own run (what ``goby-launch usv.launch`` runs)."""
    return parse_file(TRAIL_DIR / f"{vehicle.kind}.launch").entries


USV_FRONTSEAT = "usv_frontseat"  # the launcher (and host) of the USV's frontseat computer when it has two


@dataclass(frozen=True)
class HostPlan:
    """Where each launcher of a run goes (one platform per host, docs/hosts.md): ``hosts`` by launcher name
    (``topside``, ``usv``, ``auv<i>``, and ``usv_frontseat`` when ``split_usv``), the console's address (where the
    demo's recorders connect from), and the subnet the links accept datagrams from."""

    hosts: dict[str, Host]
    console: str
    peers: str
    split_usv: bool = False
    broker_port: int = 11144

    @staticmethod
    def names(n_auvs: int, split_usv: bool = False) -> list[str]:
        """The hosts a run needs, in launch order."""
        names = [v.name for v in fleet(n_auvs)]
        return [*names[:2], USV_FRONTSEAT, *names[2:]] if split_usv else names

    @classmethod
    def from_network(cls, network: HostNetwork, split_usv: bool = False, broker_port: int = 11144) -> HostPlan:
        return cls(dict(network.hosts), network.console, str(network.subnet), split_usv, broker_port)

    def address(self, vehicle: Vehicle) -> str:
        """The vehicle's address: its (backseat) host's, where its MOOSDB and, over TCP, its broker listen."""
        return self.hosts[vehicle.name].address

    def uses_tcp(self, vehicle: Vehicle) -> bool:
        return self.split_usv and vehicle.kind == "usv"

    def environment(self, launcher: str) -> dict[str, str]:
        """The TRAIL_* variables that put a launcher's configs on its host: links, pages and MOOSDB on the host's
        address, links accepting only the hosts' subnet, and for the two-computer USV the TCP broker."""
        host = self.hosts[launcher]
        vehicle_host = self.hosts["usv"] if launcher == USV_FRONTSEAT else host
        env = {"TRAIL_LINK_ADDRESS": host.address, "TRAIL_LIAISON_ADDRESS": host.address,
               "TRAIL_MOOS_ADDRESS": vehicle_host.address, "TRAIL_LINK_PEERS": self.peers,
               "TRAIL_USV_ADDRESS": self.hosts["usv"].address}  # where the AUVs' moos-share send NODE_REPORT
        if self.split_usv and launcher in ("usv", USV_FRONTSEAT):
            env |= {"TRAIL_BROKER_ADDRESS": vehicle_host.address, "TRAIL_BROKER_PORT": str(self.broker_port)}
        return env

    def interprocess(self, vehicle: Vehicle, settings: TrailSettings) -> InterProcessPortalConfig:
        """How the demo's portal threads reach the vehicle's broker: its IPC socket (the filesystem is shared
        across namespaces), or TCP to the two-computer USV's backseat."""
        cfg = InterProcessPortalConfig(platform=vehicle.name, manager_timeout_seconds=30)
        if self.uses_tcp(vehicle):
            cfg.transport = InterProcessPortalConfig.TCP
            cfg.ipv4_address = self.address(vehicle)
            cfg.tcp_port = self.broker_port
        else:
            cfg.socket_name = vehicle.ipc_base(settings)
        return cfg


def hosts_launch_entries(n_auvs: int, plan: HostPlan) -> list[LaunchEntry]:
    """all.launch with each platform's goby-launch started inside its host (``ip netns exec``) with that host's
    variables; with ``split_usv`` the USV is usv_backseat.launch and usv_frontseat.launch on two hosts."""
    entries = []
    for entry in all_launch_entries(n_auvs):
        name = entry.name or ""
        parts = [(name, entry.command)]
        if plan.split_usv and name == "usv":
            back = entry.command.replace("/usv.launch", "/usv_backseat.launch").replace(" -d 100 ", " -d 100 -p usv ")
            front = back.replace("/usv_backseat.launch", "/usv_frontseat.launch").replace(" -p usv ",
                                                                                        f" -p {USV_FRONTSEAT} ")
            parts = [(name, back), (USV_FRONTSEAT, front)]
        for launcher, command in parts:
            host = plan.hosts[launcher]
            env = entry.env + tuple(plan.environment(launcher).items())
            entries.append(dataclasses.replace(entry, name=launcher, command=host.shell_prefix + command, env=env))
    return entries


def use_interprocess(thread: BackgroundPortalThread, cfg: InterProcessPortalConfig) -> None:
    """Point a demo portal thread (PortalWorker: built with an IPC base) at ``cfg`` before it starts.
    TODO(lead): an ``interprocess`` argument of that class would replace this."""
    thread._cfg.interprocess.CopyFrom(cfg)  # type: ignore[attr-defined]


def _tcp_open(address: str, port: int) -> bool:
    try:
        with socket.create_connection((address, port), timeout=1.0):
            return True
    except OSError:
        return False


@dataclass
class VehicleRun:
    """One vehicle's logs, read as they grow (``logs``), and what they held so far (``record``)."""

    vehicle: Vehicle
    logs: PlatformLogs
    record: MissionRecord = field(default_factory=MissionRecord)

    def interface_states(self) -> list[str]:
        return [e.value for e in self.record.events_named("interface_state", source="interface")]

    def command_time(self) -> float | None:
        return command_time(self.record)


def command_time(record: MissionRecord) -> float | None:
    """When the vehicle's frontseat interface first reported COMMAND (None: never)."""
    return next((e.t for e in record.events_named("interface_state", source="interface")
                 if e.value == COMMAND_STATE), None)


@dataclass
class TrailResult:
    """What the demo prints and the tests assert: per-vehicle records read from the logs after the run (t=0 when the
    last vehicle reached COMMAND), how every launcher and process ended, unexpected error lines, what failed, and
    the log files read (``logs``: platform -> its .goby and .alog)."""

    records: dict[str, MissionRecord]
    command_times: dict[str, float | None]
    t0: float
    outcomes: list[ProcessOutcome] = field(default_factory=list)
    log_errors: list[str] = field(default_factory=list)
    failure: str | None = None
    deaths: list[tuple[float, str, str]] = field(default_factory=list)  # (t, launcher, log tail) with keep_going
    logs: dict[str, list[Path]] = field(default_factory=dict)
    origin: float = 0.0  # the mission clock's origin: t0 + origin is t=0 on the logs' time base (Unix time x warp)


class TrailMission:
    """One run. ``start()``, ``wait_for_command()``, ``run()``, and always ``stop()`` (or use ``with``).

    ``entries`` defaults to all.launch for ``n_auvs``; ``vehicles`` (default: the whole fleet) are the ones
    recorded. The run's environment is the settings' ``TRAIL_*`` variables, so every config line agrees.
    """

    def __init__(
        self,
        settings: TrailSettings,
        n_auvs: int,
        *,
        entries: Sequence[LaunchEntry] | None = None,
        vehicles: Sequence[Vehicle] | None = None,
        extra_env: dict[str, str] | None = None,
        report: Callable[[str], None] = print,
        launch_delay_s: float = 1.0,
        platform: str = "trail",
        keep_going: bool = False,
        moos_variables: tuple[str, ...] | None = None,
        hosts: HostPlan | None = None,
    ) -> None:
        self.settings = settings
        self.n_auvs = n_auvs
        self.hosts = hosts  # one platform per host (docs/hosts.md); None: all on this machine
        self.entries = list(entries) if entries is not None else (
            all_launch_entries(n_auvs) if hosts is None else hosts_launch_entries(n_auvs, hosts))
        self.extra_env = dict(extra_env or {})
        self.report = report
        self.launch_delay_s = launch_delay_s
        self.platform = platform
        # keep_going: a platform whose launcher dies (it stops its own processes first) is noted in ``deaths`` and
        # the other platforms run on; otherwise the first death ends the run.
        self.keep_going = keep_going
        self.moos_variables = moos_variables  # the MOOS variables read from the alogs (None: track, helm, commands)
        self.deaths: list[tuple[float, str, str]] = []  # (sim time, launcher, last lines of its log)
        self.clock = SimClock(settings.warp)
        self.runs = {}
        for v in vehicles if vehicles is not None else fleet(n_auvs):
            record = MissionRecord()
            logs = PlatformLogs(v.log_dir(settings), v.name, settings.warp, record, moos=v.kind != "topside",
                                moos_variables=moos_variables, node_status=v.kind == "topside",
                                origin=self.clock.origin)
            self.runs[v.name] = VehicleRun(v, logs, record)
        self.group: ProcessGroup | None = None
        self.log_dir = settings.run_dir / "logs" / "launch"
        # Set from any thread or a signal handler to end start-up, the wait for COMMAND, or the run.
        self.stop_event = threading.Event()
        self.t0: float | None = None
        self._result: TrailResult | None = None
        self._hooks: list[Callable[[], None]] = []

    # -- start -------------------------------------------------------------------------------------------------

    def environment(self) -> dict[str, str]:
        env = child_environment() | self.settings.to_env() | self.extra_env
        env[LAUNCH_DIR_VAR] = str(TRAIL_DIR)
        env[LOG_DIR_VAR] = str(self.log_dir)
        env[PLATFORM_VAR] = self.platform
        env.setdefault(N_AUVS_VAR, str(self.n_auvs))
        return env

    def start(self) -> None:
        """Start the launch lines (the loggers among them) and wait for every broker."""
        self.settings.run_dir.mkdir(parents=True, exist_ok=True)
        self.group = ProcessGroup(
            self.entries,
            self.log_dir,
            platform=self.platform,
            launch_delay_s=self.launch_delay_s,
            kill_timeout_s=30.0,
            base_env=self.environment(),
            cwd=self.settings.run_dir,
            report=self.report,
            parallel_stop=True,
        )
        self.group.stop_event = self.stop_event
        self.group.on_wait = self.poll_logs
        self.group.start()
        # The outer launch returns once the inner launchers run; their brokers come up a little later (the demo's
        # portal threads need them).
        self.wait_for_brokers()

    def wait_for_brokers(self, timeout_s: float = 120.0) -> None:
        """Block until every recorded vehicle's broker has its manager socket (portal clients time out otherwise)."""
        deadline = time.monotonic() + timeout_s
        hosts = self.hosts

        def up(run: VehicleRun) -> bool:
            if hosts is not None and hosts.uses_tcp(run.vehicle):
                return _tcp_open(hosts.address(run.vehicle), hosts.broker_port)
            return Path(ipc_manager_path(run.vehicle.ipc_base(self.settings))).exists()

        while missing := [name for name, run in self.runs.items() if not up(run)]:
            if self.stop_event.is_set():
                return
            self.poll()
            if time.monotonic() > deadline:
                raise LaunchError(f"no broker for {', '.join(missing)} within {timeout_s:g} s (logs in {self.log_dir})")
            time.sleep(0.1)

    def add_hook(self, hook: Callable[[], None]) -> None:
        """Called on every poll (the demo's commander and link counters)."""
        self._hooks.append(hook)

    # -- watch -------------------------------------------------------------------------------------------------

    def poll_logs(self) -> None:
        """Read what every platform's loggers appended since the last poll."""
        for run in self.runs.values():
            run.logs.poll()

    def poll(self) -> None:
        """Read the logs, run the hooks, and check that every launcher is alive (raises ProcessDiedError)."""
        self.poll_logs()
        for hook in self._hooks:
            hook()
        assert self.group is not None
        died = self.group.check()
        while died is not None:
            if not self.keep_going:
                raise ProcessDiedError(died.name, died.returncode, died.log_tail(40))
            self.deaths.append((self.now(), died.name, died.log_tail(40)))
            self.report(f"{died.name} died (exit status {died.returncode}); the other platforms keep running")
            died = self.group.check()

    def now(self) -> float:
        return self.clock.now()

    def missing_command(self) -> list[str]:
        dead = {name for _, name, _ in self.deaths}
        return [name for name, run in self.runs.items()
                if run.vehicle.kind != "topside" and run.command_time() is None and name not in dead]

    def wait_for_command(self, timeout_s: float = 180.0, progress: Callable[[], None] | None = None) -> float | None:
        """Block until every recorded vehicle's frontseat interface reports COMMAND; returns that sim time."""
        deadline = time.monotonic() + timeout_s
        next_progress = time.monotonic() + 5
        while self.missing_command():
            if self.stop_event.is_set():
                return None
            self.poll()
            if time.monotonic() > deadline:
                seen = {n: ", ".join(dict.fromkeys(self.runs[n].interface_states())) or "none"
                        for n in self.missing_command()}
                raise LaunchError(f"not under helm command within {timeout_s:g} s: "
                                  + "; ".join(f"{n} (states seen: {s})" for n, s in seen.items())
                                  + f"; logs in {self.log_dir}")
            if progress is not None and time.monotonic() >= next_progress:
                progress()
                next_progress = time.monotonic() + 5
            time.sleep(0.05)
        times = [run.command_time() for run in self.runs.values() if run.vehicle.kind != "topside"]
        self.t0 = max((t for t in times if t is not None), default=self.now())
        return self.t0

    def run(self, duration_s: float | None, progress: Callable[[float], None] | None = None,
            progress_period_s: float = 5.0, until: Callable[[], bool] | None = None) -> None:
        """Run for ``duration_s`` sim seconds after t0 (None: until stopped), or until ``until()`` is true."""
        t0 = self.t0 if self.t0 is not None else self.wait_for_command()
        if t0 is None:
            return
        next_progress = 0.0
        while not self.stop_event.is_set():
            self.poll()
            elapsed = self.now() - t0
            if progress is not None and time.monotonic() >= next_progress:
                progress(elapsed)
                next_progress = time.monotonic() + progress_period_s
            if duration_s is not None and elapsed >= duration_s:
                return
            if until is not None and until():
                return
            time.sleep(0.1)

    # -- stop --------------------------------------------------------------------------------------------------

    def stop(self, failure: str | None = None) -> TrailResult:
        """Stop the launch lines (each inner launcher stops its own processes first), then read every platform's
        logs whole: the result's records are those (t=0 when the last vehicle reached COMMAND)."""
        if self._result is not None:
            return self._result
        end = self.now()  # the run ends here: the logs go on while the processes stop
        for run in self.runs.values():
            run.logs.close()
        ended: list[ProcessOutcome] = []
        if self.group is not None:
            self.group.stop()
            ended = outcomes(self.group.processes)
        logs = sorted(self.log_dir.rglob("*.log")) if self.log_dir.is_dir() else []
        errors = scan_log_files((str(p.relative_to(self.log_dir)), p) for p in logs)
        records: dict[str, MissionRecord] = {}
        paths: dict[str, list[Path]] = {}
        for name, run in self.runs.items():
            read = read_platform(run.vehicle.log_dir(self.settings), name, self.settings.warp,
                                 moos=run.vehicle.kind != "topside", moos_variables=self.moos_variables,
                                 node_status=run.vehicle.kind == "topside", origin=self.clock.origin)
            records[name] = until(read.record, end)
            paths[name] = [p for p in (read.goby_path, read.alog_path) if p is not None]
        command_times = {name: command_time(record) for name, record in records.items()}
        under_command = [t for name, t in command_times.items() if t is not None and name != "topside"]
        t0 = max(under_command) if under_command else (self.t0 if self.t0 is not None else 0.0)
        self._result = TrailResult(
            records={name: shifted(record, t0) for name, record in records.items()},
            command_times={name: None if t is None else t - t0 for name, t in command_times.items()},
            t0=t0,
            outcomes=ended,
            log_errors=errors,
            failure=failure,
            deaths=[(t - t0, name, tail) for t, name, tail in self.deaths],
            logs=paths,
            origin=self.clock.origin,
        )
        return self._result

    def __enter__(self) -> TrailMission:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def auv_slice_env(vehicle: Vehicle) -> dict[str, str]:
    """The course's variables for one AUV launched on its own."""
    return {N_AUVS_VAR: str(vehicle.n_auvs), AUV_INDEX_VAR: str(vehicle.index)}


def log_path(mission: TrailMission, platform: str, program: str) -> Path:
    """A process's log in a run: ``<log dir>/<platform>/<platform>.<program>.log`` (nested) or flat."""
    nested = mission.log_dir / platform / f"{platform}.{program}.log"
    return nested if nested.exists() else mission.log_dir / f"{platform}.{program}.log"



def _ports_free(ports: Sequence[int], kind: socket.SocketKind = socket.SOCK_STREAM) -> bool:
    for port in ports:
        with socket.socket(socket.AF_INET, kind) as sock:
            try:
                sock.bind(("127.0.0.1", port))
            except OSError:
                return False
    return True


def with_free_ports(settings: TrailSettings, n_auvs: int, prefer_course: bool = True) -> TrailSettings:
    """The settings with MOOS/simulator/liaison port bases and link ports whose every port is free now, and a free
    AIS port and moos-share port base.

    The course's values first (when ``prefer_course``), else random ones, so side-by-side runs and tests do not
    collide with a mission someone else is running. The AIS and moos-share ports are chosen on their own (the
    course's 54000 and 9300 first), so a busy AIS port does not move the MOOS ports.
    """
    ids = range(n_auvs + 2)
    options = [(9000, 55000, 50000, 54500)] if prefer_course else []
    rng = random.Random()
    for _ in range(50):
        # below the kernel's ephemeral range (32768+), so no outgoing connection takes a port between check and use
        base = rng.randrange(10000, 16000, 100)
        options.append((base, base + 5000, base + 10000, base + 15000))
    for moos, sim, liaison, link in options:
        ports = [*(moos + i for i in ids), *(sim + i for i in ids), *(liaison + i for i in ids), link, link + 1]
        if not _ports_free(ports):
            continue
        ais = next((p for p in [*([54000] if prefer_course else []), *range(liaison + 300, liaison + 400)]
                    if _ports_free([p])), None)
        share = next((b for b in [*([9300] if prefer_course else []), *range(moos + 300, moos + 400, 10)]
                      if _ports_free([b + i for i in ids], socket.SOCK_DGRAM)), None)
        if ais is not None and share is not None:
            return settings.replace(moos_port_base=moos, sim_port_base=sim, liaison_port_base=liaison,
                                    satellite_port=link, acomms_port=link + 1, share_port_base=share, ais_port=ais)
    raise LaunchError("no free port range for the mission's MOOSDBs, simulators and pages")
