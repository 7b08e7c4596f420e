"""The live stack for the translator tests: MOOSDB + broker + moos-gateway (our four plugins) + usv-manager.

Module-scoped (set up before the per-test leak check, torn down after a module's last test), and parametrised
over our moos-db and, inside a private network namespace with /opt/moos/bin on PATH, the real MOOSDB.
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from translator_procs import (
    gateway_args,
    moosdb,
    plugin_env,
    running,
    wait_showing_logs,
)

from gateway.goby.portal.testing import BrokerProcess, PortalClient, broker_process
from gateway.moos.testing import connected_comms, real_moos_skip_reason
from translators.usv import groups as usv_groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from util.process import ChildProcess

PLUGINS = "frontseat:usv_command:node_report:libgoby_coroner_moos_gateway_plugin.so"
STARTUP_TIMEOUT_S = 90.0


@dataclass
class Stack:
    """What the tests talk to; ``children`` are attached to assertion messages."""

    workdir: Path
    moos_port: int
    broker: BrokerProcess
    children: list[ChildProcess] = field(default_factory=list)

    def env(self) -> dict[str, str]:
        return self.broker.env()

    def logs(self) -> str:
        return "\n".join(f"--- {c.name} ---\n{c.output()[-3000:]}" for c in self.children)


def _probe_command_path(stack: Stack) -> None:
    """Send WAYPOINTS commands on the shore group until CommandTranslation acknowledges one."""
    with PortalClient(stack.broker.interprocess_config(), name="probe") as client:
        acks = client.collect(usv_groups.usv_command_ack, USVCommandAck)
        assert client.wait_subscribed(), "probe could not subscribe at the broker"
        deadline = time.monotonic() + STARTUP_TIMEOUT_S
        while True:
            stamp = time.time()
            client.publish(usv_groups.shore_usv_command, USVCommand(time=stamp, desired_state=USVCommand.WAYPOINTS))
            done = client.poll_until(lambda s=stamp: any(
                a.command_time == s and a.stage == USVCommandAck.POSTED_TO_MOOS for a in acks), 1.0)
            if done:
                return
            if time.monotonic() > deadline:
                raise AssertionError(f"the command path never acknowledged a probe\n{stack.logs()}")


def _probe_translator_clients(stack: Stack, count: int = 3) -> None:
    """Wait until ``count`` translator MOOS clients post GOBY_MOOS_TRANSLATOR_TIME (connected, looping)."""
    sources: set[str] = set()
    with connected_comms(stack.moos_port, "probe_time", register=["GOBY_MOOS_TRANSLATOR_TIME"]) as watcher:
        def enough() -> bool:
            sources.update(m.source() for m in watcher.fetch())
            return len(sources) >= count
        wait_showing_logs(enough, STARTUP_TIMEOUT_S, f"{count} translators posting GOBY_MOOS_TRANSLATOR_TIME",
                   *stack.children)


@pytest.fixture(scope="module", params=["ours", "real"])
def stack(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Stack]:
    if request.param == "real":
        reason = real_moos_skip_reason("MOOSDB")
        if reason:
            pytest.skip(reason)
    workdir = tmp_path_factory.mktemp(f"stack_{request.param}")
    with contextlib.ExitStack() as exits:
        port = exits.enter_context(moosdb(request.param, workdir))
        broker = exits.enter_context(broker_process(workdir, platform="usv"))
        built = Stack(workdir, port, broker)
        built.children.append(exits.enter_context(
            running("moos_gateway", gateway_args(port), workdir, plugin_env(broker.env(), PLUGINS))))
        built.children.append(exits.enter_context(
            running("usv_manager", [sys.executable, "-m", "translators.apps.usv_manager", "-vv"], workdir, broker.env())))
        _probe_translator_clients(built)
        _probe_command_path(built)
        yield built
        for child in built.children:
            assert child.running, f"{child.name} died during the tests\n{built.logs()}"
