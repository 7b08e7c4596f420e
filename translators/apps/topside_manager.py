"""topside-manager: the Goby3 course's goby3_course_topside_manager (see ``translators.trail.topside_manager.TopsideManager``)."""

from __future__ import annotations

from gateway.goby.portal import run_application
from translators.trail.protobuf.manager_config_pb2 import TopsideManager as TopsideManagerConfig
from translators.trail.topside_manager import TopsideManager


def main(argv: list[str] | None = None) -> int:
    """Console script ``topside-manager``: Goby-style config file / ``--interprocess`` / ``GOBY_INTERPROCESS``."""
    return run_application(TopsideManager, TopsideManagerConfig, argv, prog="topside-manager")


if __name__ == "__main__":
    raise SystemExit(main())
