"""``python -m launch.trail.moos_gen PLATFORM``: the course's ``config/moos_gen.sh`` (usv or auv).

Writes ``<run_dir>/<platform>.moos`` and ``.bhv`` (through ``launch.trail.config``), then waits; on SIGTERM or
SIGINT it removes both and exits 0, because "MOOS applications can't handle process substitution" and the
files must not outlive the mission. The MOOS lines of the launch file generate the same files themselves
(atomically, same content), so they never wait on this line's start-up; this line owns their removal.
"""

from __future__ import annotations

import os
import shlex
import sys
import threading
from pathlib import Path

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
    if stop.is_set():
        _remove(paths)
        return 0
    # The wait is the course's shell script's: a shell sleeping with a trap costs ~1 MiB, where this interpreter
    # with its imports costs 9 MiB of private memory on every platform for the whole mission. The shell says
    # "wrote" once its trap is set, so whoever waits for that line may stop it from then on.
    files = " ".join(shlex.quote(str(p)) for p in paths)
    names = " and ".join(str(p) for p in paths)
    on_stop = f"kill $! 2>/dev/null; rm -f {files}; echo {shlex.quote('removed ' + names)}; exit 0"
    script = (f"trap {shlex.quote(on_stop)} TERM INT; echo {shlex.quote('wrote ' + names)}; "
              "while :; do sleep 3600 & wait $!; done")
    sys.stdout.flush()
    os.execv("/bin/sh", ["/bin/sh", "-c", script])


def _remove(paths: tuple[Path, ...]) -> None:
    for path in paths:
        path.unlink(missing_ok=True)
    print("removed " + " and ".join(str(p) for p in paths), flush=True)


if __name__ == "__main__":
    sys.exit(main())
