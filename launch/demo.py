"""What the headless mission demos (``python -m launch.usv.demo``, ``python -m launch.trail.demo``) share.

Both demos are runnable modules (apps, not libraries): argument checks and the shared options, the run directory,
the mission's run under SIGINT/SIGTERM handling, and ``main``.
"""

from __future__ import annotations

import argparse
import importlib
import shlex
import shutil
import sys
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Protocol, TypeVar

from launch.errors import LaunchError, MissionConfigError
from util.logsetup import configure_logging
from util.process import handle_signals

ResultT = TypeVar("ResultT", covariant=True)


class Mission(Protocol[ResultT]):
    """A mission runner as the demos drive it (``UsvMission``, ``TrailMission``)."""

    stop_event: threading.Event

    def stop(self, failure: str | None = None) -> ResultT: ...


def plotting(module: str, picture: str) -> ModuleType:
    """A demo's plot module, imported only when a run needs it: matplotlib is the optional ``[demo]`` extra, so
    ``--help`` and bad arguments work without it. Raises :class:`LaunchError` naming the extra when it is missing
    (call it before any process starts: no mission run that cannot draw its ``picture``)."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if (exc.name or "").partition(".")[0] != "matplotlib":
            raise
        raise LaunchError(f"the demo draws {picture} with matplotlib, which is not installed: install the [demo] "
                          f"extra ({shlex.quote(sys.executable)} -m pip install -e '.[demo]', or run make demo)") from None


def whole_number(low: int, high: int | None = None) -> Callable[[str], int]:
    """An argparse ``type=``: a whole number >= ``low`` (and <= ``high`` when given)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
        if high is None and value < low:
            raise argparse.ArgumentTypeError(f"must be >= {low}, not {value}")
        if high is not None and not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be {low}..{high}, not {value}")
        return value

    return parse


def schedule_type(parse_schedule: Callable[[str], object]) -> Callable[[str], str]:
    """An argparse ``type=`` that checks a schedule with the runner's own parser, so a schedule the runner would
    refuse is refused before anything starts; the value stays the text."""

    def check(text: str) -> str:
        try:
            parse_schedule(text)
        except MissionConfigError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
        return text

    return check


def add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """``--out``, ``--moosdb`` and ``--helm`` (see ``launch.mission.choose_program``)."""
    parser.add_argument("--out", type=Path, default=Path("out"), help="output directory (default ./out)")
    parser.add_argument("--moosdb", choices=("auto", "real", "ours"), default="auto",
                        help="MOOSDB when on PATH (auto), force it (real) or our moos-db (ours)")
    parser.add_argument("--helm", choices=("auto", "real", "ours"), default="auto",
                        help="pHelmIvP when on PATH (auto), force it (real) or our ivp-helm (ours)")


def fresh_run_dir(out: Path, socket_prefix: str, max_socket_base: int) -> tuple[Path, Path]:
    """``(run_dir, socket_dir)``: ``out/run`` emptied, and where the IPC sockets go: the run directory, or a new
    directory under /tmp when the run directory's path is too long for AF_UNIX (about 107 bytes)."""
    run_dir = out / "run"
    if run_dir.exists():
        shutil.rmtree(run_dir)
    if len(str(run_dir)) < max_socket_base:
        return run_dir, run_dir
    return run_dir, Path(tempfile.mkdtemp(prefix=socket_prefix, dir="/tmp"))


def run_mission(mission: Mission[ResultT], body: Callable[[], None], run_dir: Path, socket_dir: Path,
                before_stop: Callable[[], None] = lambda: None) -> tuple[ResultT, str | None]:
    """Run ``body`` (which starts and runs ``mission``) with SIGINT/SIGTERM setting ``mission.stop_event``; a
    ``LaunchError`` ends it with one line on stderr. Then ``before_stop()``, stop the mission, restore the signal
    handlers and remove a socket directory of its own. Returns the mission's result and the failure, if any."""
    failure = None
    with handle_signals(lambda _signum: mission.stop_event.set()):
        try:
            body()
        except LaunchError as exc:
            failure = str(exc)
            print(f"demo: {exc}", file=sys.stderr, flush=True)
        finally:
            before_stop()
            result = mission.stop(failure)
    if socket_dir != run_dir:
        shutil.rmtree(socket_dir, ignore_errors=True)
    return result, failure


def demo_main(parser: argparse.ArgumentParser, run_demo: Callable[[argparse.Namespace], int], app_name: str,
              argv: list[str] | None) -> int:
    """A demo's ``main``: parse ``argv``, set up logging, run; a ``LaunchError`` is one line and exit status 1."""
    args = parser.parse_args(argv)
    configure_logging(args.verbose, app_name)
    try:
        return run_demo(args)
    except LaunchError as exc:
        print(f"demo: {exc}", file=sys.stderr)
        return 1
