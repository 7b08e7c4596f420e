"""Drive a :class:`Helm` and a :class:`KinematicModel` in simulated time, with no MOOS at all.

A tiny stand-in for the MOOSDB echo: every helm posting to a variable the helm registered comes back
as mail (source = the helm), as the real DB would deliver it.
"""

from __future__ import annotations

from pathlib import Path

from behaviors.helm.helm import Helm, Post
from behaviors.helm.testing import DOMAIN, helm_from_text

from .kinematic_vehicle import KinematicModel


def make_helm(tmp_path: Path, bhv_text: str, domains=DOMAIN, **params: str) -> Helm:
    """A helm for ``bhv_text``; the file stays in ``tmp_path`` for a failing test to show."""
    return helm_from_text(bhv_text, domains, directory=tmp_path, **params)


class CoreLoop:
    """Simulated time: the helm iterates every ``tick`` s; the model integrates in ``tick/5`` steps."""

    def __init__(self, helm: Helm, model: KinematicModel | None = None, tick: float = 0.25) -> None:
        self.helm, self.model, self.tick = helm, model or KinematicModel(), tick
        self.t = 1000.0
        self.posts: list[tuple[float, Post]] = []
        self.registered = helm.registrations()
        self._deliver(helm.startup(self.t))

    def _deliver(self, posts: list[Post]) -> None:
        for post in posts:
            self.posts.append((self.t, post))
            if isinstance(post.value, float) and post.var == "DESIRED_HEADING":
                self.model.desired_heading = post.value
            elif isinstance(post.value, float) and post.var == "DESIRED_SPEED":
                self.model.desired_speed = post.value
            elif isinstance(post.value, float) and post.var == "DESIRED_DEPTH":
                self.model.desired_depth = post.value
            if post.var in self.registered:
                self._deliver(self.helm.handle_mail(post.var, post.value, self.t, self.helm.app_name, self.t))

    def poke(self, var: str, value: float | str) -> None:
        self._deliver(self.helm.handle_mail(var, value, self.t, "uPokeDB", self.t))

    def run(self, seconds: float, until=None) -> bool:
        """Advance ``seconds`` of simulated time (or until ``until()`` holds; returns whether it did)."""
        end = self.t + seconds
        while self.t < end:
            m = self.model
            for var, value in (("NAV_X", m.x), ("NAV_Y", m.y), ("NAV_HEADING", m.heading),
                               ("NAV_SPEED", m.speed), ("NAV_DEPTH", m.depth)):
                self.helm.handle_mail(var, value, self.t, "uSim", self.t)
            self._deliver(self.helm.iterate(self.t))
            for _ in range(5):
                self.t += self.tick / 5
                self.model.step(self.tick / 5, self.t)
            if until is not None and until():
                return True
        return until is None

    def values(self, var: str) -> list[float | str]:
        return [p.value for _, p in self.posts if p.var == var]

    def last(self, var: str) -> float | str | None:
        vals = self.values(var)
        return vals[-1] if vals else None
