"""goby-liaison: a platform's web page (scope, commander, map), Goby3's goby_liaison config and URLs.

    goby-liaison <config> [--http_port 50001] [--http_address 127.0.0.1] [-v]

Binds ``http_address`` (Goby's default ``localhost``).  Listening on another address (``--http_address
0.0.0.0``) lets anyone who reaches it read every message and send commands to the vehicle: the page has no
authentication.  Prints ``goby-liaison ready: <url> ...`` once serving.
"""

from __future__ import annotations

import sys

from gateway.goby.portal import run_application
from launch.liaison.portal_side import LiaisonApp
from launch.liaison.protobuf import liaison_web_pb2  # noqa: F401 - registers the [..web] config extension
from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig

PROG = "goby-liaison"


def main(argv: list[str] | None = None) -> int:
    """Console script ``goby-liaison``."""
    return run_application(LiaisonApp, LiaisonConfig, argv, prog=PROG)


if __name__ == "__main__":
    sys.exit(main())
