"""``ivp-helm`` with one injected fault, run as a child process by ``test_helm_app.py``.

``python faulty_helm.py FAULT VAR MISSION [ivp-helm options]``. The faults stand in for bugs the app must
survive or report; the real helm has no known input that triggers them:

The helm also registers for ``VAR``.

- ``mail VAR``: handling mail to ``VAR`` raises;
- ``post VAR``: mail to ``VAR`` makes the helm post an unpostable value to ``VAR``, then ``FAULT_AFTER=VAR``;
- ``startup -``: the helm's start-up raises (the helm thread cannot serve on).
"""

from __future__ import annotations

import sys

from behaviors.apps import ivp_helm as app
from behaviors.helm.helm import Helm, Post


class InjectedFault(RuntimeError):
    """The fault this script injects (its cause is a ``ValueError``, to show the cause is logged)."""


def _fault(what: str) -> InjectedFault:
    try:
        raise ValueError(f"root cause of {what}")
    except ValueError as cause:
        fault = InjectedFault(f"injected fault: {what}")
        fault.__cause__ = cause
        return fault


def inject(fault: str, var: str) -> None:
    handle_mail, startup, registrations = Helm.handle_mail, Helm.startup, Helm.registrations

    def faulty_registrations(self: Helm) -> set[str]:
        return registrations(self) | {var}

    def faulty_handle_mail(self: Helm, name: str, *args, **kwargs) -> list[Post]:
        if name == var and fault == "mail":
            raise _fault(f"mail {name}")
        if name == var and fault == "post":
            return [Post(var, None), Post("FAULT_AFTER", var)]  # type: ignore[arg-type]
        return handle_mail(self, name, *args, **kwargs)

    def faulty_startup(self: Helm, now: float) -> list[Post]:
        if fault == "startup":
            raise _fault("startup")
        return startup(self, now)

    Helm.handle_mail = faulty_handle_mail  # type: ignore[method-assign]
    Helm.startup = faulty_startup  # type: ignore[method-assign]
    Helm.registrations = faulty_registrations  # type: ignore[method-assign]


if __name__ == "__main__":
    inject(sys.argv[1], sys.argv[2])
    raise SystemExit(app.main(sys.argv[3:]))
