"""auv-manager: the Goby3 course's goby3_course_auv_manager (see ``translators.trail.auv_manager.AUVManager``)."""

from __future__ import annotations

from gateway.goby.portal import run_application
from translators.trail.auv_manager import AUVManager
from translators.trail.protobuf.manager_config_pb2 import AUVManager as AUVManagerConfig


def main(argv: list[str] | None = None) -> int:
    """Console script ``auv-manager``: Goby-style config file / ``--interprocess`` / ``GOBY_INTERPROCESS``."""
    return run_application(AUVManager, AUVManagerConfig, argv, prog="auv-manager")


if __name__ == "__main__":
    raise SystemExit(main())
