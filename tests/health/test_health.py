"""Health answers, goby-coroner and goby-terminate with real processes on a real goby-broker (docs/health.md)."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from gateway.goby.portal.health import HEALTH_REPORT, HEALTH_REQUEST, HEALTH_RESPONSE
from gateway.goby.portal.protobuf.coroner_pb2 import (
    ERROR__PROCESS_DIED,
    ERROR__THREAD_NOT_RESPONDING,
    HEALTH__FAILED,
    HEALTH__OK,
    HealthRequest,
    ProcessHealth,
    VehicleHealth,
)
from gateway.goby.portal.protobuf.terminate_pb2 import TerminateResult
from gateway.goby.portal.terminate import TERMINATE_RESULT
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process, broker_process
from util.process import ChildProcess

APP = [sys.executable, "-m", "tests.health.apps.health_app"]


@pytest.fixture
def broker(tmp_path: Path) -> Iterator[BrokerProcess]:
    with broker_process(tmp_path, platform="healthy") as running:
        yield running


@pytest.fixture
def client(broker: BrokerProcess) -> Iterator[PortalClient]:
    with PortalClient(broker.interprocess_config()) as portal:
        yield portal


def start_app(broker: BrokerProcess, tmp_path: Path, role: str, name: str) -> ChildProcess:
    app = app_process([*APP, f"--role={role}", "--app", f'name: "{name}"'], tmp_path / f"{name}.log", env=broker.env())
    app.wait_ready("READY")
    return app


def ask_health(client: PortalClient, name: str, timeout_s: float = 20.0) -> ProcessHealth:
    """Publish HealthRequests until ``name`` answers; its answer."""
    answers: list[ProcessHealth] = []
    client.subscribe(HEALTH_RESPONSE, ProcessHealth, lambda a: answers.append(a) if a.name == name else None)
    assert client.wait_subscribed()
    try:
        def answered() -> bool:
            client.publish(HEALTH_REQUEST, HealthRequest())
            return client.poll_until(lambda: bool(answers), 1.5)

        assert client.poll_until(answered, timeout_s), f"{name} never answered a health request"
    finally:
        client.portal.unsubscribe(HEALTH_RESPONSE, ProcessHealth)
    return answers[0]


def test_single_thread_application_answers_health(broker: BrokerProcess, client: PortalClient,
                                                  tmp_path: Path) -> None:
    app = start_app(broker, tmp_path, "single", "lonely")
    try:
        answer = ask_health(client, "lonely")
        assert answer.pid == app.pid
        assert answer.main.name == "lonely"
        assert answer.main.state == HEALTH__OK
        assert answer.main.HasField("thread_id") and answer.main.thread_id > 0
        assert not answer.main.child
    finally:
        assert app.stop() == 0


def test_threads_answer_and_a_hung_thread_is_not_responding(broker: BrokerProcess, client: PortalClient,
                                                            tmp_path: Path) -> None:
    app = start_app(broker, tmp_path, "threads", "busy")
    try:
        answer = ask_health(client, "busy")
        assert answer.pid == app.pid and answer.main.name == "busy" and answer.main.state == HEALTH__OK
        children = {c.name.rsplit(".", 1)[-1]: c for c in answer.main.child}
        assert sorted(children) == ["Hanger", "Worker"]
        assert [children["Worker"].uid, children["Hanger"].uid] == [0, 1]
        assert all(c.state == HEALTH__OK and not c.HasField("error") for c in children.values())
        thread_ids = {answer.main.thread_id, *(c.thread_id for c in children.values())}
        assert len(thread_ids) == 3 and 0 not in thread_ids  # each answered from its own thread

        client.publish("hang", "now")
        assert app.wait_for_output("HANGING", timeout=20) is not None
        answer = ask_health(client, "busy")
        children = {c.name.rsplit(".", 1)[-1]: c for c in answer.main.child}
        assert children["Hanger"].state == HEALTH__FAILED
        assert children["Hanger"].error == ERROR__THREAD_NOT_RESPONDING
        assert children["Worker"].state == HEALTH__OK
        assert answer.main.state == HEALTH__FAILED
    finally:
        assert app.stop() == 0  # the hung thread is released when the application ends


def test_coroner_reports_ok_then_process_died(broker: BrokerProcess, client: PortalClient, tmp_path: Path) -> None:
    victim = start_app(broker, tmp_path, "single", "victim")
    report_file = tmp_path / "coroner.txt"
    reports = client.collect(HEALTH_REPORT, VehicleHealth)
    assert client.wait_subscribed()
    coroner = app_process(
        [sys.executable, "-m", "gateway.apps.goby_coroner", "--expected_name", "victim", "--request_interval", "1",
         "--response_timeout", "0.5", "--report_file", str(report_file)],
        tmp_path / "coroner.log", env=broker.env())
    try:
        def victim_state() -> tuple[int, int, int] | None:
            if not reports:
                return None
            process = {p.name: p for p in reports[-1].process}["victim"]
            error = process.main.error if process.main.HasField("error") else 0
            return reports[-1].state, process.main.state, error

        assert client.poll_until(lambda: victim_state() == (HEALTH__OK, HEALTH__OK, 0), 30), victim_state()
        report = reports[-1]
        assert report.platform == "healthy" and report.time > 0
        assert [p.pid for p in report.process] == [victim.pid]
        victim.kill()
        died = (HEALTH__FAILED, HEALTH__FAILED, ERROR__PROCESS_DIED)
        assert client.poll_until(lambda: victim_state() == died, 30), victim_state()
        assert reports[-1].process[0].main.error_message == "Process victim has died"
        lines = report_file.read_text().splitlines()
        assert all(line.startswith("goby-coroner/healthy          [") for line in lines)
        assert any(line.endswith("]: HEALTH__OK") for line in lines)
        assert any(line.endswith('HEALTH__FAILED; victim: "Process victim has died"') for line in lines)
    finally:
        assert coroner.stop() == 0
        victim.stop()


def run_terminate(broker: BrokerProcess, tmp_path: Path, *args: str) -> ChildProcess:
    terminate = app_process([sys.executable, "-m", "gateway.apps.goby_terminate", *args],
                            tmp_path / "terminate.log", env=broker.env())
    terminate.wait(60)
    return terminate


def test_terminate_by_name_stops_exactly_that_app(broker: BrokerProcess, client: PortalClient,
                                                  tmp_path: Path) -> None:
    target = start_app(broker, tmp_path, "threads", "target")
    bystander = start_app(broker, tmp_path, "single", "bystander")
    results = client.collect(TERMINATE_RESULT, TerminateResult)
    assert client.wait_subscribed()
    try:
        terminate = run_terminate(broker, tmp_path, "--target_name", "target")
        assert terminate.returncode == 0, terminate.tail()
        assert target.wait(10) == 0  # quit on its own, cleanly
        assert bystander.running
        printed = terminate.lines()
        assert f'target_name: "target" target_pid: {target.pid} result: PROCESS_RESPONDED' in printed
        assert printed[-1] == f'target_name: "target" target_pid: {target.pid} result: PROCESS_CLEANLY_QUIT'
        assert client.poll_until(lambda: any(r.result == TerminateResult.PROCESS_CLEANLY_QUIT for r in results), 10)
        assert {r.target_pid for r in results} == {target.pid}
    finally:
        target.stop()
        assert bystander.stop() == 0


def test_terminate_by_pid(broker: BrokerProcess, tmp_path: Path) -> None:
    target = start_app(broker, tmp_path, "single", "numbered")
    try:
        terminate = run_terminate(broker, tmp_path, "--target_pid", str(target.pid))
        assert terminate.returncode == 0, terminate.tail()
        assert target.wait(10) == 0
        assert terminate.lines()[-1].endswith("result: PROCESS_CLEANLY_QUIT")
    finally:
        target.stop()


def test_terminate_times_out_on_silence(broker: BrokerProcess, tmp_path: Path) -> None:
    terminate = run_terminate(broker, tmp_path, "--target_name", "nobody", "--response_timeout", "1")
    assert terminate.returncode == 1
    assert terminate.lines() == ['target_name: "nobody" result: TIMEOUT_RESPONSE']


def test_terminate_without_target_is_refused(broker: BrokerProcess, tmp_path: Path) -> None:
    terminate = run_terminate(broker, tmp_path)
    assert terminate.returncode == 1
    assert "must specify at least one --target_name or --target_pid" in terminate.stderr_text()
