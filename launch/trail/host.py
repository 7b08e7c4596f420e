"""``python -m launch.trail.host PLATFORM --address A``: one platform of the trail mission on a real computer.

Prints the command (environment and goby-launch line) that starts PLATFORM (``topside``, ``usv``, ``auv``) on this
computer with its configs on ``--address``: the links' multicast ``listen_address``, the MOOSDB and the pages bind
it; ``--peer`` (repeatable: the other computers' addresses or their network) limits the sources each link accepts.
``--run`` runs it instead of printing. Every computer of the mission must be given the same ``--auvs`` and
``--warp``. A vehicle of two computers (``--part frontseat`` / ``--part backseat``, USV only) joins its halves by
Goby's interprocess TCP transport: both are given ``--backseat``, the backseat computer's address, where the broker
and the MOOSDB listen. docs/hosts.md has the whole recipe; ``python -m launch.trail.demo --hosts`` runs the same
lines in network namespaces on one machine.
"""

from __future__ import annotations

import argparse
import ipaddress
import os
import shlex
import sys

from launch.demo import whole_number
from launch.errors import MissionConfigError
from launch.process_group import child_environment
from launch.trail.settings import AUV_INDEX_VAR, N_AUVS_VAR, REPO_ROOT, TRAIL_DIR, TrailSettings
from util.cli import HelpFormatter


def _ipv4(text: str) -> str:
    try:
        return str(ipaddress.IPv4Address(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an IPv4 address: {text!r}") from None


def _network(text: str) -> str:
    try:
        return str(ipaddress.IPv4Network(text, strict=False))
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an IPv4 address or network: {text!r}") from None


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog="python -m launch.trail.host",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("platform", choices=("topside", "usv", "auv"))
    parser.add_argument("--address", type=_ipv4, required=True, help="this computer's address on the vehicles' network")
    parser.add_argument("--peer", type=_network, action="append", default=[], metavar="ADDRESS[/BITS]",
                        help="another computer of the mission (or their network); the links drop datagrams from "
                        "anything else (default: accept any source)")
    parser.add_argument("--auvs", type=whole_number(0, 250), default=4, help="number of AUVs in the mission (default 4)")
    parser.add_argument("--index", type=whole_number(0, 249), default=0, help="this AUV's index (auv only)")
    parser.add_argument("--warp", type=whole_number(1), default=TrailSettings.warp, help="time warp, the same everywhere")
    parser.add_argument("--part", choices=("frontseat", "backseat"), default=None,
                        help="the USV on two computers: this one runs its frontseat (simulator and interface) or "
                        "the rest (broker, MOOS, helm, links); needs --backseat")
    parser.add_argument("--backseat", type=_ipv4, default=None,
                        help="with --part: the backseat computer's address (its broker's TCP transport and MOOSDB)")
    parser.add_argument("--broker-port", type=whole_number(1, 65535), default=TrailSettings.broker_port,
                        help=f"with --part: the broker's TCP port (default {TrailSettings.broker_port})")
    parser.add_argument("--usv", type=_ipv4, default=None, metavar="ADDRESS",
                        help="auv: the USV's (backseat) computer, where this AUV's moos-share sends its NODE_REPORTs "
                        "(without it they are not shared)")
    parser.add_argument("--run-dir", default="/tmp/goby3_course_trail", help="where configs and logs go")
    parser.add_argument("--pages-on-address", action="store_true",
                        help="goby-liaison listens on --address (RISK: no login) instead of 127.0.0.1")
    parser.add_argument("--run", action="store_true", help="run the platform instead of printing the command")
    return parser


def platform_command(args: argparse.Namespace) -> tuple[dict[str, str], list[str]]:
    """The variables and the goby-launch command line that start the platform; MissionConfigError on a bad mix."""
    if args.part is not None and (args.platform != "usv" or args.backseat is None):
        raise MissionConfigError("--part is for the USV only, and needs --backseat (the backseat computer's address)")
    if args.platform == "auv" and args.index >= args.auvs:
        raise MissionConfigError(f"--index {args.index} is not below --auvs {args.auvs}")
    env = {
        "TRAIL_RUN_DIR": args.run_dir,
        "TRAIL_WARP": str(args.warp),
        "TRAIL_LINK_ADDRESS": args.address,
        "TRAIL_LIAISON_ADDRESS": args.address if args.pages_on_address else "127.0.0.1",
        "TRAIL_MOOS_ADDRESS": args.backseat if args.part else "127.0.0.1",
        "TRAIL_LINK_PEERS": ",".join(args.peer),
    }
    if args.platform != "topside":
        env[N_AUVS_VAR] = str(args.auvs)
    if args.platform == "auv":
        env[AUV_INDEX_VAR] = str(args.index)
        if args.usv is None:
            print("host: no --usv: this AUV's NODE_REPORTs go to 127.0.0.1, not to the USV's MOOSDB", file=sys.stderr)
        env["TRAIL_USV_ADDRESS"] = args.usv or "127.0.0.1"
    if args.platform == "usv":  # its moos-share listens where its MOOSDB does
        env["TRAIL_USV_ADDRESS"] = args.backseat if args.part else args.address
    if args.part:
        env |= {"TRAIL_BROKER_ADDRESS": args.backseat, "TRAIL_BROKER_PORT": str(args.broker_port)}
    TrailSettings.from_env(env)  # a bad value fails here, naming its variable, not in a launch line
    stem = f"usv_{args.part}" if args.part else args.platform
    name = f"auv{args.index}" if args.platform == "auv" else ("usv_frontseat" if args.part == "frontseat" else
                                                              args.platform)
    return env, ["goby-launch", "-P", "-d", "100", "-p", name, str(TRAIL_DIR / f"{stem}.launch")]


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        env, command = platform_command(args)
    except MissionConfigError as exc:
        print(f"host: {exc}", file=sys.stderr)
        return 2
    if not args.run:
        assignments = " ".join(f"{k}={shlex.quote(v)}" for k, v in env.items())
        print(f"cd {shlex.quote(str(REPO_ROOT))} && {assignments} {shlex.join(command)}")
        return 0
    os.chdir(REPO_ROOT)
    os.execvpe(command[0], command, child_environment() | env)


if __name__ == "__main__":
    sys.exit(main())
