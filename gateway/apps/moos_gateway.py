"""``moos-gateway`` (goby_moos_gateway): resolve the plugins of ``GOBY_MOOS_GATEWAY_PLUGINS``, then run the gateway.

The application itself is ``gateway.moos_gateway.application.GobyMOOSGateway``; this module only reads argv and the
environment and wires them to it.
"""

from __future__ import annotations

import sys

from gateway.goby.portal import run_application
from gateway.moos_gateway.application import APP_NAME, GobyMOOSGateway
from gateway.moos_gateway.plugins import Plugin, plugin_entries_from_env, resolve_plugins
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from util.extensions import ExtensionError

_NO_PLUGINS_NEEDED = {"-h", "--help", "-e", "--example_config"}


def main(argv: list[str] | None = None) -> int:
    """Console script ``moos-gateway [config.pb.cfg] [--moos 'server: "localhost" port: 9000'] [-v]``."""
    args = list(sys.argv[1:] if argv is None else argv)
    plugins: list[Plugin] = []
    if not _NO_PLUGINS_NEEDED.intersection(args):
        try:
            plugins = resolve_plugins(plugin_entries_from_env())
        except ExtensionError as exc:
            print(f"{APP_NAME}: {exc}", file=sys.stderr)
            return 1

    def build(cfg: GobyMOOSGatewayConfig) -> GobyMOOSGateway:
        return GobyMOOSGateway(cfg, plugins)

    return run_application(build, GobyMOOSGatewayConfig, args, prog=APP_NAME)


if __name__ == "__main__":
    sys.exit(main())
