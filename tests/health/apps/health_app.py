"""Applications run as real processes by tests/health: ``python -m tests.health.apps.health_app --role=ROLE``.

Roles:
* ``single``: a SingleThreadApplication that does nothing but answer health and terminate requests.
* ``threads``: a MultiThreadApplication with two launched threads, ``Worker`` and ``Hanger``; a string published on
  interprocess ``hang`` makes ``Hanger`` block in its callback (a hung thread) until the application ends.
"""

from __future__ import annotations

import sys
import threading

from gateway.goby.portal import MultiThreadApplication, SimpleThread, SingleThreadApplication, run_application
from tests.protobuf.sample_messages_pb2 import SampleAppConfig

HANG_GROUP = "hang"
HANG_LIMIT_S = 120.0  # a hung thread gives up on its own after this, so a failing test still ends


class SingleApp(SingleThreadApplication):
    def initialize(self) -> None:
        print("READY", flush=True)


class Worker(SimpleThread):
    pass


class Hanger(SimpleThread):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.release = threading.Event()
        self.interprocess().subscribe(HANG_GROUP, str, self.on_hang)

    def on_hang(self, _text: str) -> None:
        print("HANGING", flush=True)
        self.release.wait(HANG_LIMIT_S)


class ThreadsApp(MultiThreadApplication):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.launch_thread(Worker)
        self.hanger = self.launch_thread(Hanger)

    def initialize(self) -> None:
        print("READY", flush=True)

    def finalize(self) -> None:
        assert isinstance(self.hanger, Hanger)
        self.hanger.release.set()


ROLES = {"single": SingleApp, "threads": ThreadsApp}


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    role = next((a.split("=", 1)[1] for a in args if a.startswith("--role=")), "single")
    args = [a for a in args if not a.startswith("--role=")]
    return run_application(ROLES[role], SampleAppConfig, args, prog=f"health_{role}")


if __name__ == "__main__":
    sys.exit(main())
