"""``python -m launch.trail.moos_gen PLATFORM``: the course's ``config/moos_gen.sh`` (usv or auv).

Writes ``<run_dir>/<platform>.moos`` and ``.bhv`` (through ``launch.trail.config``), then waits; on SIGTERM or
SIGINT it removes both and exits 0, because "MOOS applications can't handle process substitution" and the
files must not outlive the mission. The MOOS lines of the launch file generate the same files themselves
(atomically, same content), so they never wait on this line's start-up; this line owns their removal.
"""

from __future__ import annotations

import sys
import threading

from launch.config import fail
from launch.errors import MissionConfigError
from launch.trail.config import write_moos_files
from launch.trail.settings import TrailSettings, vehicle_from_env
from util.process import handle_signals


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1 or args[0] not in ("usv", "auv"):
        return fail("usage: python -m launch.trail.moos_gen usv|auv")
    with handle_signals() as stop:
        return _write_and_wait(args[0], stop)


def _write_and_wait(vehicle: str, stop: threading.Event) -> int:
    try:
        settings = TrailSettings.from_env()
        paths = write_moos_files(settings, vehicle_from_env(vehicle))
    except MissionConfigError as exc:
        return fail(str(exc))
    print("wrote " + " and ".join(str(p) for p in paths), flush=True)
    try:
        while not stop.wait(3600):
            pass
    finally:
        for path in paths:
            path.unlink(missing_ok=True)
        print("removed " + " and ".join(str(p) for p in paths), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
