"""Helm benchmark: cost of one decision iteration, and closed-loop accuracy in simulated time.

``python -m bench.bench_helm``. No MOOS: the helm core is driven directly at AppTick 4 against a small
kinematic vehicle (turn rate 30 deg/s, acceleration 0.5 m/s^2), so the figures are deterministic.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

from behaviors.helm.helm import Helm
from behaviors.helm.testing import helm_from_text

REPO = Path(__file__).resolve().parents[1]
SURVEY = """\
Behavior = BHV_Waypoint
{
  name = survey
  speed = 2.0
  capture_radius = 5
  slip_radius = 0
  points = 40,0:40,50:-20,50:-20,10
}
"""


class Vehicle:
    def __init__(self, x: float = 0.0, y: float = 0.0, heading: float = 0.0) -> None:
        self.x, self.y, self.heading, self.speed = x, y, heading, 0.0
        self.track: list[tuple[float, float]] = []

    def step(self, dt: float, heading: float, speed: float) -> None:
        err = (heading - self.heading + 180) % 360 - 180
        self.heading = (self.heading + max(-30 * dt, min(30 * dt, err))) % 360
        self.speed += max(-0.5 * dt, min(0.5 * dt, speed - self.speed))
        self.x += self.speed * math.sin(math.radians(self.heading)) * dt
        self.y += self.speed * math.cos(math.radians(self.heading)) * dt
        self.track.append((self.x, self.y))


def make_helm(bhv_text: str, speed_max: str = "4") -> Helm:
    return helm_from_text(bhv_text, ("course:0:359:360", f"speed:0:{speed_max}:41"), ownship="bench",
                          where="bench", start_engaged="true")


def run(helm: Helm, vehicle: Vehicle, seconds: float, pokes: dict[str, str] | None = None) -> float:
    """Simulate; returns the mean wall-clock cost of one helm iteration in microseconds."""
    t, desired, cost, n = 0.0, {"DESIRED_HEADING": 0.0, "DESIRED_SPEED": 0.0}, 0.0, 0
    helm.startup(t)
    for var, poke in (pokes or {}).items():
        helm.handle_mail(var, poke, t, "bench", t)
    while t < seconds:
        for var, value in (("NAV_X", vehicle.x), ("NAV_Y", vehicle.y), ("NAV_HEADING", vehicle.heading),
                           ("NAV_SPEED", vehicle.speed)):
            helm.handle_mail(var, value, t, "sim", t)
        start = time.perf_counter()
        posts = helm.iterate(t)
        cost += time.perf_counter() - start
        n += 1
        for post in posts:
            if post.var in desired and isinstance(post.value, float):
                desired[post.var] = post.value
        for _ in range(5):
            vehicle.step(0.05, desired["DESIRED_HEADING"], desired["DESIRED_SPEED"])
        t += 0.25
    return 1e6 * cost / n


def main() -> int:
    rows = []
    helm, vehicle = make_helm(SURVEY), Vehicle()
    us = run(helm, vehicle, 200)
    misses = [min(math.hypot(x - px, y - py) for x, y in vehicle.track)
              for px, py in [(40, 0), (40, 50), (-20, 50), (-20, 10)]]
    rows.append(("waypoint survey, 4 points", f"{us:.0f}", "closest approach (m): " +
                 ", ".join(f"{m:.1f}" for m in misses) + " (capture radius 5)"))
    helm = make_helm((REPO / "behaviors" / "usv.bhv").read_text(), "2")
    vehicle = Vehicle(0, -120, 0)
    helm.handle_mail("POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=60,pts=6", 0, "bench", 0)
    us = run(helm, vehicle, 900)
    radii = [math.hypot(x, y) for x, y in vehicle.track[len(vehicle.track) // 3:]]
    rows.append(("usv.bhv loiter, hexagon r=60", f"{us:.0f}",
                 f"ring radius min/mean/max (m): {min(radii):.1f}/{sum(radii) / len(radii):.1f}/{max(radii):.1f}"
                 f" (edge 52.0, vertex 60.0)"))
    width = max(len(r[0]) for r in rows)
    print(f"{'scenario':<{width}}  {'us/iter':>8}  accuracy")
    for name, cost, acc in rows:
        print(f"{name:<{width}}  {cost:>8}  {acc}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
