"""``goby-launch``: run the processes of a goby_launch launch file, like goby3's ``goby_launch -r``.

Processes start in order with a delay (``-d`` ms), each with its own log file (``-L`` directory);
the launcher reports every few seconds which are up. Ctrl-C or SIGTERM stops them in reverse order: as
goby_launch, with goby-terminate by default when the file has exactly one broker line (SIGTERM if an app has not
quit after ``-m`` seconds), else with the line's ``kill=`` signal (default SIGTERM); SIGKILL after ``-k`` seconds. If one dies, the launcher names it, shows
the tail of its log, stops the rest and exits non-zero; with ``--respawn N`` (or ``GOBY_LAUNCH_RESPAWN=N``,
which nested launchers inherit) it starts a dead process again, up to N times each, before giving up.
"""

from __future__ import annotations

import argparse
import logging
import os
import shlex
import signal
import sys
import time
from pathlib import Path

from launch.errors import LaunchError, ProcessDiedError
from launch.launchfile import parse_file
from launch.process_group import ProcessGroup, child_environment
from util.cli import HelpFormatter, bounded_number
from util.logsetup import add_verbosity_argument, configure_logging
from util.process import handle_signals

log = logging.getLogger(__name__)

PRESEED = "preseed.goby"  # sourced before each command when it sits next to the launch file, as goby_launch does
# Exported to every child: the launch file's directory (so a launch file of launch files names its neighbours
# wherever it is started from) and the log directory (so a nested goby-launch without -L logs beneath it).
LAUNCH_DIR_VAR = "GOBY_LAUNCH_DIR"
LOG_DIR_VAR = "GOBY_LAUNCH_LOG_DIR"
PLATFORM_VAR = "GOBY_LAUNCH_PLATFORM"  # the platform name (-p), for name= directives
RESPAWN_VAR = "GOBY_LAUNCH_RESPAWN"  # default of --respawn; inherited by nested launchers (not in goby_launch)
_respawn_count = bounded_number(int, 0)  # --respawn and GOBY_LAUNCH_RESPAWN: a whole number >= 0
_UNSUPPORTED_MODES = {
    "screen": "-s (GNU screen)",
    "nohup": "-n (nohup)",
    "xterm": "-x (xterm)",
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        formatter_class=HelpFormatter,
        prog="goby-launch",
        description="Launch the processes of a goby_launch launch file; Ctrl-C stops them in reverse order.",
    )
    parser.add_argument("launchfile", help="one command per line, optional [kill=..., env=K=V, name=..] prefix")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("-r", dest="mode", action="store_const", const="normal", help="run in this terminal (default)")
    mode.add_argument("-s", dest="mode", action="store_const", const="screen", help="not supported here")
    mode.add_argument("-n", dest="mode", action="store_const", const="nohup", help="not supported here")
    mode.add_argument("-x", dest="mode", action="store_const", const="xterm", help="not supported here")
    parser.add_argument("-d", dest="delay_ms", type=float, default=10.0, help="delay between launches, ms (10)")
    parser.add_argument("-k", dest="kill_s", type=float, default=10.0, help="SIGKILL after this many s (10)")
    parser.add_argument("-m", dest="terminate_s", type=float, default=10.0, help="SIGTERM after goby_terminate for this many s (10)")
    parser.add_argument("-p", dest="platform", default=None, help="platform name (default: launch file stem)")
    parser.add_argument("-P", dest="parallel", action="store_true", help="stop all processes at once")
    parser.add_argument("-L", dest="log_dir", default=None, help="log directory (default /tmp/goby_launch_<platform>_<time>)")
    parser.add_argument("-b", dest="background", action="store_true", help="not supported here")
    parser.add_argument("--status-period", type=float, default=5.0, help="seconds between status lines (5)")
    parser.add_argument("--startup-check", type=float, default=1.0, help="seconds to watch after the last launch (1)")
    parser.add_argument("--respawn", type=_respawn_count, default=None, metavar="N",
                        help=f"start a process that dies again, up to N times each (default ${RESPAWN_VAR} or 0: "
                        "the first death stops everything, as goby_launch does)")
    add_verbosity_argument(parser)
    return parser


def default_log_dir(platform: str, environ: dict[str, str] | os._Environ[str]) -> str:
    """``<parent's log dir>/<platform>`` under a parent goby-launch, else ``/tmp/goby_launch_<platform>_<UTC time>``."""
    parent = environ.get(LOG_DIR_VAR)
    if parent:
        return str(Path(parent) / platform)
    return f"/tmp/goby_launch_{platform}_{time.strftime('%Y%m%dT%H%M%S', time.gmtime())}"


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    configure_logging(args.verbose, "goby-launch")
    if args.mode in _UNSUPPORTED_MODES or args.background:
        flag = _UNSUPPORTED_MODES.get(args.mode, "-b (background)")
        print(f"goby-launch: {flag} is not supported; processes run here with a log file each (-L)", file=sys.stderr)
        return 2
    try:
        launch_file = parse_file(args.launchfile)
    except LaunchError as exc:
        print(f"goby-launch: {exc}", file=sys.stderr)
        return 1
    try:
        respawn_limit = args.respawn if args.respawn is not None else _respawn_count(os.environ.get(RESPAWN_VAR, "0"))
    except argparse.ArgumentTypeError as exc:
        print(f"goby-launch: {RESPAWN_VAR}: {exc}", file=sys.stderr)
        return 2
    platform = args.platform or Path(args.launchfile).stem
    log_dir = default_log_dir(platform, os.environ) if args.log_dir is None else args.log_dir
    env = child_environment()
    env[LAUNCH_DIR_VAR] = str(Path(args.launchfile).resolve().parent)
    env[LOG_DIR_VAR] = str(Path(log_dir).resolve())
    env[PLATFORM_VAR] = platform
    group = ProcessGroup(
        launch_file.entries,
        log_dir,
        platform=platform,
        launch_delay_s=args.delay_ms / 1000.0,
        kill_timeout_s=args.kill_s,
        startup_check_s=args.startup_check,
        base_env=env,
        parallel_stop=args.parallel,
        terminate_timeout_s=args.terminate_s,
    )
    preseed = Path(args.launchfile).resolve().parent / PRESEED
    preamble = f"source {shlex.quote(str(preseed))} || exit 1" if preseed.is_file() else ""
    if preamble:
        print(f"Sourcing {preseed} before each command", flush=True)
    group.preamble = preamble
    print(f"Logs in {log_dir}", flush=True)
    def on_signal(signum: int) -> None:  # in a signal handler: flags only, the main thread reports
        group.request_stop(f"\nReceived {signal.Signals(signum).name}")

    with handle_signals(on_signal):
        try:
            group.start()
        except ProcessDiedError as exc:
            print(f"goby-launch: failed to launch: {exc}", file=sys.stderr, flush=True)
            return 1
        except LaunchError as exc:
            group.stop()
            print(f"goby-launch: {exc}", file=sys.stderr, flush=True)
            return 1
        print("Use <CTRL+C> to exit", flush=True)
        return group.supervise(status_period_s=args.status_period, respawn_limit=respawn_limit)


if __name__ == "__main__":
    sys.exit(main())
