"""``goby-interfaces``: write interface YAML from our code, and draw deployments (goby_clang_tool's role).

    goby-interfaces generate APP [-o FILE | --outdir DIR]     # APP: a shipped app name or a dotted module
    goby-interfaces generate --all [--outdir DIR]             # every shipped app (docs/interfaces by default)
    goby-interfaces visualize DEPLOYMENT.yml [-o FILE] [--no-disconnected] [--format svg|png|pdf]
"""

from __future__ import annotations

import argparse
import logging
import shutil
import subprocess
import sys
from pathlib import Path

from launch.interfaces.analyze import AnalysisError
from launch.interfaces.catalog import SHIPPED_APPLICATIONS, generate_text, interface_file_name
from launch.interfaces.deployment import DEFAULT_INTERFACES_DIR, DeploymentError, load_deployment
from launch.interfaces.visualize import VizOptions, build_graph, to_dot
from util.cli import HelpFormatter
from util.logsetup import add_verbosity_argument, configure_logging

log = logging.getLogger(__name__)


def _generate(args: argparse.Namespace) -> int:
    if args.all == bool(args.app):
        print("generate: give one APP or --all", file=sys.stderr)
        return 1
    apps = sorted(SHIPPED_APPLICATIONS) if args.all else [args.app]
    outdir = Path(args.outdir) if args.outdir else (DEFAULT_INTERFACES_DIR if args.all else Path("."))
    outdir.mkdir(parents=True, exist_ok=True)
    for app in apps:
        try:
            text = generate_text(app)
        except (AnalysisError, ImportError) as exc:
            print(f"generate {app}: {exc}", file=sys.stderr)
            return 1
        target = Path(args.output) if args.output and not args.all else outdir / interface_file_name(app)
        target.write_text(text)
        print(f"wrote {target}")
    return 0


def _visualize(args: argparse.Namespace) -> int:
    try:
        deployment = load_deployment(args.deployment)
    except DeploymentError as exc:
        print(f"visualize: {exc}", file=sys.stderr)
        return 1
    options = VizOptions(
        no_disconnected=args.no_disconnected,
        omit_group_regex=args.omit_group_regex,
        omit_node_regex=args.omit_node_regex,
        include_terminate=args.include_terminate or args.include_all,
        include_coroner=args.include_coroner or args.include_all,
        include_all=args.include_all,
        splines=args.splines,
    )
    dot_text = to_dot(build_graph(deployment, options), options)
    outdir = Path(args.outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    dot_path = Path(args.output) if args.output else outdir / f"{deployment.name}.dot"
    dot_path.write_text(dot_text)
    print(f"wrote {dot_path}")
    if args.format:
        dot = shutil.which("dot")
        if dot is None:
            print("visualize: Graphviz `dot` is not installed; wrote DOT only (apt-get install graphviz)", file=sys.stderr)
            return 0
        image = dot_path.with_suffix(f".{args.format}")
        subprocess.run([dot, f"-T{args.format}", str(dot_path), "-o", str(image)], check=True)
        print(f"wrote {image}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(formatter_class=HelpFormatter, prog="goby-interfaces", description=__doc__.splitlines()[0])
    add_verbosity_argument(parser)
    sub = parser.add_subparsers(dest="action", required=True)
    gen = sub.add_parser("generate", help="write an application's interface YAML from its code")
    gen.add_argument("app", nargs="?", help="shipped application name or dotted module name")
    gen.add_argument("--all", action="store_true", help="every shipped application")
    gen.add_argument("-o", "--output", help="output file (default <app>_interface.yml)")
    gen.add_argument("--outdir", help="output directory (default . ; docs/interfaces with --all)")
    viz = sub.add_parser("visualize", help="write a deployment's Graphviz DOT (and an image with --format)")
    viz.add_argument("deployment", help="deployment YAML file")
    viz.add_argument("-o", "--output", help="output DOT file (default <deployment>.dot)")
    viz.add_argument("--outdir", default=".")
    viz.add_argument("--no-disconnected", action="store_true", help="omit unconnected pubs/subs (required subs stay)")
    viz.add_argument("--omit-group-regex")
    viz.add_argument("--omit-node-regex")
    viz.add_argument("--include-terminate", action="store_true")
    viz.add_argument("--include-coroner", action="store_true")
    viz.add_argument("--include-all", action="store_true")
    viz.add_argument("--splines", default="ortho")
    viz.add_argument("--format", choices=["svg", "png", "pdf"], help="also render with Graphviz dot")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    configure_logging(args.verbose, "goby-interfaces")
    return _generate(args) if args.action == "generate" else _visualize(args)


if __name__ == "__main__":
    sys.exit(main())
