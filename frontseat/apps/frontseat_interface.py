"""``frontseat-interface``: load the driver named by ``FRONTSEAT_DRIVER_LIBRARY`` and run the goby_frontseat_interface
application (``frontseat.interface.FrontSeatInterface``) with it; ``--help`` and ``--example_config`` need no driver."""

from __future__ import annotations

import logging
import os
import sys
import textwrap
from functools import partial
from types import ModuleType

from frontseat.errors import FrontSeatException
from frontseat.interface import FrontSeatInterface, example_config
from frontseat.loading import ENV_VAR, driver_factory, load_driver_library
from frontseat.protobuf import frontseat_interface_config_pb2 as app_pb
from gateway.goby.portal import run_application
from util.extensions import ExtensionError

log = logging.getLogger(__name__)

EXAMPLE_DRIVER = "basic_simulator"  # whose extension --example_config shows when FRONTSEAT_DRIVER_LIBRARY is unset
_HELP_OPTIONS = {"-h", "--help"}
_EXAMPLE_OPTIONS = {"-e", "--example_config"}
HELP_NOTE = (
    f"The driver comes from the environment variable {ENV_VAR}: an entry point of group "
    "goby_frontseat.drivers (e.g. basic_simulator), Goby's library name for it "
    "(libgoby_frontseat_basic_simulator.so.30), a .py file or a dotted module. --example_config shows that "
    f"driver's [extension] block in frontseat_cfg ({EXAMPLE_DRIVER}'s when {ENV_VAR} is unset). "
    "frontseat-interface-basic-simulator runs this program with basic_simulator preselected."
)


def _print_help(argv: list[str]) -> int:
    """``--help`` needs no driver: argparse prints the usage (and exits), then the note on the driver variable."""

    def no_driver(_cfg: app_pb.FrontSeatInterfaceConfig) -> FrontSeatInterface:
        raise FrontSeatException("--help runs no interface")

    try:
        code: object = run_application(no_driver, app_pb.FrontSeatInterfaceConfig, argv, prog="frontseat-interface")
    except SystemExit as exc:
        code = exc.code
    print("\n" + textwrap.fill(HELP_NOTE, 79), flush=True)
    return code if isinstance(code, int) else 0 if code is None else 1


def _print_example(spec: str | None) -> int:
    """``--example_config``: with the extension of the driver ``spec`` names, or of the basic simulator if none."""
    module: ModuleType | None
    if spec:
        print(f"Loading frontseat driver library: {spec}", file=sys.stderr)
        try:
            module = load_driver_library(spec)
        except ExtensionError as exc:
            print(f"frontseat-interface: {exc}", file=sys.stderr)
            return 1
        print(example_config(module))
        return 0
    try:
        module = load_driver_library(EXAMPLE_DRIVER)
        note = (f"# {ENV_VAR} is unset: frontseat_cfg shows the {EXAMPLE_DRIVER} driver's block; set it to a "
                "driver and run --example_config again for that driver's block")
    except ExtensionError as exc:  # not installed as a package: show the example without a driver block
        log.debug("no example driver: %s", exc)
        module = None
        note = f"# {ENV_VAR} is unset: set it to a driver and run --example_config again for that driver's block"
    print(f"{note}\n{example_config(module)}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Load the driver named by FRONTSEAT_DRIVER_LIBRARY, then run the interface (exit 1 if the driver fails).

    ``--help`` and ``--example_config`` work without the variable (see :data:`HELP_NOTE`).
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    if _HELP_OPTIONS.intersection(argv):
        return _print_help(argv)
    spec = os.environ.get(ENV_VAR)
    if _EXAMPLE_OPTIONS.intersection(argv):
        return _print_example(spec)
    if not spec:
        print(
            f"Environment variable {ENV_VAR} must be set with the name of the driver library to use "
            "(an entry point such as basic_simulator, a dotted module, or a .py file).",
            file=sys.stderr,
        )
        return 1
    print(f"Loading frontseat driver library: {spec}", file=sys.stderr)
    try:
        module = load_driver_library(spec)
        factory = driver_factory(module, spec)
    except ExtensionError as exc:
        print(f"frontseat-interface: {exc}", file=sys.stderr)
        return 1
    return run_application(
        partial(FrontSeatInterface, driver_factory=factory),
        app_pb.FrontSeatInterfaceConfig,
        argv,
        prog="frontseat-interface",
    )


if __name__ == "__main__":
    sys.exit(main())
