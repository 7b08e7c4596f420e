"""goby-broker answers health and terminate requests as gobyd does (docs/health.md): real broker, real clients."""

from __future__ import annotations

import sys
from pathlib import Path

from gateway.goby.portal.protobuf.coroner_pb2 import HEALTH__OK
from gateway.goby.portal.testing import PortalClient, app_process, broker_process
from tests.health.test_health import ask_health


def test_broker_answers_health_with_its_pid(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="brk") as broker, PortalClient(broker.interprocess_config()) as client:
        assert broker.process is not None
        answer = ask_health(client, "goby-broker")
        assert answer.pid == broker.process.pid
        assert answer.main.name == "goby-broker"
        assert answer.main.state == HEALTH__OK
        assert broker.process.running


def test_broker_answers_health_over_tcp(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="brktcp", tcp=True) as broker, \
            PortalClient(broker.interprocess_config()) as client:
        assert broker.process is not None
        assert ask_health(client, "goby-broker").pid == broker.process.pid


def test_goby_terminate_stops_the_broker_cleanly(tmp_path: Path) -> None:
    with broker_process(tmp_path, platform="brkterm") as broker:
        process = broker.process
        assert process is not None
        terminate = app_process([sys.executable, "-m", "gateway.apps.goby_terminate", "--target_name", "goby-broker"],
                                tmp_path / "terminate.log", env=broker.env())
        terminate.wait(60)
        assert terminate.returncode == 0, terminate.tail()
        assert terminate.lines()[-1] == (f'target_name: "goby-broker" target_pid: {process.pid} '
                                         "result: PROCESS_CLEANLY_QUIT"), terminate.lines()
        assert process.wait(10) == 0
