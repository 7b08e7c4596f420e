"""``frontseat-interface`` with the basic simulator driver preselected (Goby's generated wrapper script
``goby_frontseat_interface_basic_simulator``): the console script ``frontseat-interface-basic-simulator``, or
``python -m frontseat.apps.frontseat_interface_basic_simulator``. An already set ``FRONTSEAT_DRIVER_LIBRARY`` wins."""

from __future__ import annotations

import os
import sys

from frontseat.apps.frontseat_interface import main as interface_main
from frontseat.loading import ENV_VAR


def main(argv: list[str] | None = None) -> int:
    """Run the interface with ``FRONTSEAT_DRIVER_LIBRARY=basic_simulator`` unless the variable is already set."""
    os.environ.setdefault(ENV_VAR, "basic_simulator")
    return interface_main(argv)


if __name__ == "__main__":
    sys.exit(main())
