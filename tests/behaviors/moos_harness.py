"""Closed-loop harness on loopback: a MOOSDB, the helm (``ivp-helm`` process or the real pHelmIvP),
the kinematic vehicle double, and an observer client that keeps every message it sees.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from behaviors.testing import write_helm_mission
from gateway.moos import MoosClock, comms
from util.process import ChildProcess

from .kinematic_vehicle import KinematicModel, KinematicVehicle

WARP = 20.0
REPO = Path(__file__).resolve().parents[2]
IVP_HELM = Path(sys.executable).parent / "ivp-helm"

def bhv_block(kind: str, **params: object) -> str:
    """One ``Behavior = BHV_<kind> { ... }`` block of a .bhv file: ``params`` in order, then ``duration =
    no-time-limit`` unless a duration is given (``duration=None``: no duration line)."""
    params.setdefault("duration", "no-time-limit")
    lines = "".join(f"  {name:<8} = {value}\n" for name, value in params.items() if value is not None)
    return f"Behavior = BHV_{kind}\n{{\n{lines}}}\n"


def write_mission(tmp_path: Path, port: int, bhv: Path, warp: float = WARP, community: str = "alpha",
                  max_speed: str = "2", extra: str = "", app_tick: float = 4, blocks: str = "",
                  name: str = "mission.moos") -> Path:
    """The mission file at this harness's warp: see :func:`behaviors.testing.write_helm_mission`."""
    return write_helm_mission(tmp_path, port, bhv, warp=warp, community=community, max_speed=max_speed, extra=extra,
                              app_tick=app_tick, blocks=blocks, name=name)


class Observer:
    """A MOOS client that keeps (time, name, value, source) of everything it registered for."""

    def __init__(self, port: int, clock: MoosClock, names: list[str]) -> None:
        self.clock = clock
        self.comms = comms(clock=clock)
        self.mail: list[tuple[float, str, float | str, str]] = []
        self.comms.set_on_connect_callback(lambda: all(self.comms.register(n, 0) for n in names))
        self.comms.run("127.0.0.1", port, "test_observer")
        if not self.comms.wait_until_connected(10000):
            self.comms.close(True)
            raise TimeoutError("observer could not connect")

    def poll(self) -> None:
        for msg in self.comms.fetch():
            value = msg.double() if msg.is_double() else msg.string()
            self.mail.append((msg.time(), msg.key(), value, msg.source()))

    def values(self, name: str) -> list[float | str]:
        self.poll()
        return [v for _, n, v, _ in self.mail if n == name]

    def last(self, name: str) -> float | str | None:
        vals = self.values(name)
        return vals[-1] if vals else None

    def wait(self, predicate: Callable[[], object], timeout: float = 60.0) -> bool:
        """Poll until ``predicate()`` holds (generous real-time timeout; the caller asserts the result)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self.poll()
            if predicate():
                return True
            time.sleep(0.02)
        self.poll()
        return bool(predicate())

    def wait_moos(self, seconds: float, timeout: float = 60.0) -> None:
        """Let ``seconds`` of MOOS time pass."""
        end = self.clock.time() + seconds
        self.wait(lambda: self.clock.time() >= end, timeout)

    def post(self, name: str, value: float | str) -> None:
        self.comms.notify(name, value)

    def close(self) -> None:
        self.comms.close(True)


@contextlib.contextmanager
def helm_process(mission: Path, tmp_path: Path, command: list[str] | None = None,
                 env: dict[str, str] | None = None) -> Iterator[ChildProcess]:
    """``ivp-helm MISSION`` (or ``command``) as a child process logging to ``helm.log``, with ``env`` added to this
    process's environment; stopped (SIGTERM, then SIGKILL) on exit."""
    with ChildProcess(command or [str(IVP_HELM), str(mission), "-v"], tmp_path / "helm.log", cwd=tmp_path,
                      env={**os.environ, **(env or {})}) as proc:
        yield proc


@contextlib.contextmanager
def vehicle(port: int, clock: MoosClock, **start: float) -> Iterator[KinematicVehicle]:
    sim = KinematicVehicle(port, clock, KinematicModel(**start))
    sim.start()
    try:
        yield sim
    finally:
        sim.stop()


@contextlib.contextmanager
def observer(port: int, clock: MoosClock, names: list[str]) -> Iterator[Observer]:
    obs = Observer(port, clock, names)
    try:
        yield obs
    finally:
        obs.close()


def polygon_center(view_polygon: str) -> tuple[float, float]:
    """Bounding-box centre of a ``pts={x,y:...}`` spec (VIEW_POLYGON)."""
    body = view_polygon.split("{", 1)[1].split("}", 1)[0]
    pts = [tuple(float(v) for v in p.split(",")[:2]) for p in body.split(":")]
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    return (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2


def ring_stats(track, cx: float, cy: float, since: float) -> tuple[float, float, float]:
    """(min, max distance from (cx, cy), signed bearing swept around it; + is clockwise) after ``since``."""
    pts = [(x, y) for t, x, y, _, _ in track if t >= since]
    radii = [math.hypot(x - cx, y - cy) for x, y in pts]
    swept = 0.0
    for (x1, y1), (x2, y2) in zip(pts, pts[1:], strict=False):
        a1 = math.degrees(math.atan2(x1 - cx, y1 - cy))
        a2 = math.degrees(math.atan2(x2 - cx, y2 - cy))
        swept += (a2 - a1 + 180) % 360 - 180
    return min(radii), max(radii), swept


def stopped_threads_ok() -> bool:
    return all(not t.name.startswith(("helm-", "kinematic")) for t in threading.enumerate())
