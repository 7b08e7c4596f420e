"""Test double for a vehicle simulator (uSimMarine's job): a kinematic model that follows DESIRED_*.

``KinematicModel`` holds the state and moves it with the basic frontseat simulator's own dynamics
(``frontseat.simulator.model.step_dynamics``); ``KinematicVehicle`` runs it as a MOOS client on its own thread,
subscribing DESIRED_HEADING/SPEED/DEPTH and posting NAV_X/Y/HEADING/SPEED/DEPTH. It is a stand-in for
the real frontseat simulator path, which the launcher tests exercise end to end.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field

from frontseat.simulator.model import Kinematics, VehicleConfig, step_dynamics
from gateway.moos import MoosClock, comms


@dataclass
class KinematicModel:
    """Heading turns at a bounded rate, speed changes at a bounded acceleration, position integrates."""

    x: float = 0.0
    y: float = 0.0
    heading: float = 0.0
    speed: float = 0.0
    depth: float = 0.0
    turn_rate: float = 30.0  # deg/s
    accel: float = 0.5  # m/s^2
    z_rate: float = 1.0  # m/s
    desired_heading: float = 0.0
    desired_speed: float = 0.0
    desired_depth: float = 0.0
    track: list[tuple[float, float, float, float, float]] = field(default_factory=list)

    def step(self, dt: float, t: float) -> None:
        """One step of the frontseat simulator's dynamics (``step_dynamics``) with this model's rate limits."""
        vehicle = Kinematics(x=self.x, y=self.y, z=-self.depth, v=self.speed, hdg=self.heading)
        desired = Kinematics(z=-self.desired_depth, v=self.desired_speed, hdg=self.desired_heading)
        step_dynamics(vehicle, desired, VehicleConfig(accel=self.accel, hdg_rate=self.turn_rate, z_rate=self.z_rate),
                      dt)
        self.x, self.y, self.depth, self.speed = vehicle.x, vehicle.y, -vehicle.z, max(0.0, vehicle.v)
        self.heading = vehicle.hdg % 360.0
        self.track.append((t, self.x, self.y, self.heading, self.speed))


class KinematicVehicle:
    """The model as a MOOS app on its own thread; ``track`` holds (moos_time, x, y, heading, speed)."""

    def __init__(self, port: int, clock: MoosClock, model: KinematicModel | None = None,
                 name: str = "uSimKinematic", real_period: float = 0.02, host: str = "127.0.0.1") -> None:
        self.model = model or KinematicModel()
        self.clock, self.port, self.name, self.host = clock, port, name, host
        self.real_period = real_period
        self.comms = comms(clock=clock)
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None

    @property
    def track(self) -> list[tuple[float, float, float, float, float]]:
        with self._lock:
            return list(self.model.track)

    def start(self) -> KinematicVehicle:
        self.comms.set_on_connect_callback(
            lambda: all(self.comms.register(v, 0) for v in ("DESIRED_HEADING", "DESIRED_SPEED", "DESIRED_DEPTH")))
        self.comms.run(self.host, self.port, self.name)
        if not self.comms.wait_until_connected(10000):
            self.comms.close(True)
            raise TimeoutError("kinematic vehicle could not connect")
        self._thread = threading.Thread(target=self._run, name="kinematic-vehicle", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(10)
        self.comms.close(True)

    def __enter__(self) -> KinematicVehicle:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _run(self) -> None:
        last = self.clock.time()
        while not self._stop.is_set():
            for msg in self.comms.fetch():
                if not msg.is_double():
                    continue
                if msg.key() == "DESIRED_HEADING":
                    self.model.desired_heading = msg.double()
                elif msg.key() == "DESIRED_SPEED":
                    self.model.desired_speed = msg.double()
                elif msg.key() == "DESIRED_DEPTH":
                    self.model.desired_depth = msg.double()
            now = self.clock.time()
            with self._lock:
                self.model.step(min(now - last, 2.0), now)
            last = now
            m = self.model
            for var, value in (("NAV_X", m.x), ("NAV_Y", m.y), ("NAV_HEADING", m.heading),
                               ("NAV_SPEED", m.speed), ("NAV_DEPTH", m.depth)):
                self.comms.notify(var, round(value, 3))
            time.sleep(self.real_period)
