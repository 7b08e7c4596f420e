"""Threads and applications in one process: call_soon, interthread, launch/join, loop frequency with warp,
interprocess from a non-main thread, loop errors, signals, and the interface registry."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from gateway.goby.portal import (
    InvalidGroupError,
    MultiThreadApplication,
    SimpleThread,
    SingleThreadApplication,
    SystemClock,
    ThreadError,
)
from gateway.goby.portal.interface_registry import ENV_VAR, read_entries
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process, running_app
from tests.protobuf.sample_messages_pb2 import Sample, SampleAppConfig
from util.process import wait_until

REPO = Path(__file__).resolve().parents[2]


class Worker(SimpleThread):
    """Records the thread its callbacks run on."""

    def __init__(self, cfg: SampleAppConfig, group: str = "work") -> None:
        super().__init__(cfg, loop_frequency_hz=0)
        self.ident = threading.get_ident()
        self.seen: list[tuple[int, int]] = []
        self.interthread().subscribe(group, Sample, lambda m: self.seen.append((m.a, threading.get_ident())))


def no_interprocess_cfg() -> Any:
    """An app config type without an interprocess field, so the app needs no broker."""
    from gateway.goby.protobuf.app_config_pb2 import AppConfig

    return AppConfig(name="standalone")


class InterthreadOnly(MultiThreadApplication):
    pass


def test_call_soon_runs_on_owning_thread_and_wakes_it() -> None:
    with running_app(InterthreadOnly, no_interprocess_cfg()) as app:
        worker = app.launch_thread(Worker, SampleAppConfig())
        where: list[int] = []
        done = threading.Event()
        start = time.monotonic()
        worker.call_soon(lambda: (where.append(threading.get_ident()), done.set()))
        assert done.wait(10)
        elapsed = time.monotonic() - start
        assert where == [worker.ident] != [threading.get_ident()]
        assert elapsed < 1.0  # the thread has no loop: only the wake-up can have run it
        worker.call_soon(lambda: 1 / 0)  # logged, the thread keeps serving
        worker.call_soon(done.clear)
        wait_until(lambda: not done.is_set(), 20, "not done.is_set()")
        assert app.join_thread(Worker) == 1


def test_interthread_delivers_on_subscriber_threads_without_echo() -> None:
    with running_app(InterthreadOnly, no_interprocess_cfg()) as app:
        w1 = app.launch_thread(Worker, SampleAppConfig())
        w2 = app.launch_thread(Worker, SampleAppConfig())
        for a in range(1, 4):
            w1.call_soon(lambda a=a: w1.interthread().publish("work", Sample(a=a)))
        wait_until(lambda: len(w2.seen) == 3, 20, "len(w2.seen) == 3")
        time.sleep(0.1)
        assert [a for a, _ in w2.seen] == [1, 2, 3]
        assert {t for _, t in w2.seen} == {w2.ident}
        assert w1.seen == []  # the publisher does not get its own interthread publication
        with pytest.raises(InvalidGroupError):
            w1.interthread().publish("", Sample())


class RegexWorker(SimpleThread):
    def __init__(self, cfg: Any) -> None:
        super().__init__(cfg)
        self.hits: list[tuple[str, str, int]] = []
        self.interthread().subscribe_regex(lambda obj, scheme, tname, group: self.hits.append((group, tname, scheme)),
                                           group_regex="work|other", type_regex=".*Sample")


def test_interthread_regex_subscription() -> None:
    with running_app(InterthreadOnly, no_interprocess_cfg()) as app:
        rx = app.launch_thread(RegexWorker, SampleAppConfig())
        tx = app.launch_thread(Worker, SampleAppConfig())
        for group in ("work", "other", "workx"):
            tx.call_soon(lambda g=group: tx.interthread().publish(g, Sample(a=1)))
        tx.call_soon(lambda: tx.interthread().publish("other", "a string"))
        tx.call_soon(lambda: tx.interthread().publish("other", Sample(a=2)))
        wait_until(lambda: len(rx.hits) == 3, 20, "len(rx.hits) == 3")
        time.sleep(0.1)
    assert rx.hits == [("work", "goby.test.zeromq.protobuf.Sample", 5), ("other", "goby.test.zeromq.protobuf.Sample", 5),
                       ("other", "goby.test.zeromq.protobuf.Sample", 5)]


class Broken(SimpleThread):
    def __init__(self, cfg: Any) -> None:
        raise RuntimeError("no hardware")


class LoopFails(SimpleThread):
    def __init__(self, cfg: Any) -> None:
        super().__init__(cfg, loop_frequency_hz=50)

    def loop(self) -> None:
        raise RuntimeError("bug in loop")


def test_launch_errors_and_loop_errors() -> None:
    with running_app(InterthreadOnly, no_interprocess_cfg()) as app:
        with pytest.raises(ThreadError, match="Broken failed to start: no hardware"):
            app.launch_thread(Broken)
        app.launch_thread(LoopFails)
        wait_until(lambda: app.return_code == 1 and not app.alive, 20, "app.return_code == 1 and not app.alive")


class Ticker(SingleThreadApplication):
    def __init__(self, cfg: Any) -> None:
        super().__init__(cfg, loop_frequency_hz=10)
        self.ticks = 0

    def loop(self) -> None:
        self.ticks += 1


def test_loop_frequency_is_multiplied_by_warp() -> None:
    with running_app(Ticker, no_interprocess_cfg(), clock=SystemClock(True, 5)) as app:
        assert app.effective_loop_frequency_hz() == 50
        start, first = time.monotonic(), app.ticks
        time.sleep(1.0)
        rate = (app.ticks - first) / (time.monotonic() - start)
    assert 15 < rate <= 55  # 50 Hz warped; 10 Hz unwarped would be at most ~11


class PortalThread(SimpleThread):
    """Subscribes interprocess from a launched (non-main) thread."""

    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.ident = threading.get_ident()
        self.got: list[tuple[int, int]] = []
        self.interprocess().subscribe("from_test", Sample, self.on_sample)

    def on_sample(self, msg: Sample) -> None:
        self.got.append((msg.a, threading.get_ident()))
        self.interprocess().publish("from_thread", Sample(a=msg.a * 10))


class PortalApp(MultiThreadApplication):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.worker = self.launch_thread(PortalThread)


def test_non_main_thread_uses_interprocess_with_callbacks_on_its_thread(broker: BrokerProcess) -> None:
    cfg = SampleAppConfig()
    cfg.app.name = "portal_app"
    cfg.interprocess.CopyFrom(broker.interprocess_config())
    with running_app(PortalApp, cfg) as app, PortalClient(broker.interprocess_config(), "pt_client") as client:
        answers = client.collect("from_thread", Sample)
        assert client.wait_subscribed()
        wait_until(lambda: not app.interprocess().hold_state(), 20, "not app.interprocess().hold_state()")
        a = 0

        def answered() -> bool:
            nonlocal a
            a += 1
            client.publish("from_test", Sample(a=a))
            return client.poll_until(lambda: bool(answers), 0.1)

        assert client.poll_until(answered, 20)
        worker = app.worker
    assert {t for _, t in worker.got} == {worker.ident}
    assert answers[0].a % 10 == 0
    registry = app.context.registry  # the application's own: nothing recorded process-wide
    entries = {(e.layer, e.direction, e.group, e.scheme, e.type, e.thread) for e in registry.entries()}
    assert ("interprocess", "subscribe", "from_test", "PROTOBUF", "goby.test.zeromq.protobuf.Sample",
            "PortalThread") in entries
    assert ("interprocess", "publish", "from_thread", "PROTOBUF", "goby.test.zeromq.protobuf.Sample",
            "PortalThread") in entries


def test_sigterm_shuts_an_app_down_cleanly_and_writes_the_registry(broker: BrokerProcess, tmp_path: Path) -> None:
    registry_file = tmp_path / "interfaces.json"
    env = broker.env()
    env[ENV_VAR] = str(registry_file)
    cmd = [sys.executable, "-m", "tests.portal.apps.sample_app", "--role=rx", "-a", "sig_rx", "-v",
           "--group", "sig", "--count", "1000"]
    with app_process(cmd, env=env, cwd=REPO, log_path=tmp_path / "rx.log") as app:
        with PortalClient(broker.interprocess_config(), "sig_tx") as tx:
            assert tx.wait_ready()

            def running() -> bool:
                tx.publish("sig", Sample(a=1))
                return app.wait_for_output("RX sig", 0.1) is not None

            assert tx.poll_until(running, 30), app.stderr_text()
        app.send_signal(signal.SIGTERM)
        assert app.wait(20) == 0
        assert "received SIGTERM; shutting down" in app.stderr_text()
    entries = read_entries(registry_file)
    assert any(e.direction == "subscribe" and e.group == "sig" and e.thread == "RxApp" and e.application == "sig_rx"
               for e in entries)


def test_example_config_of_an_app() -> None:
    out = subprocess.run([sys.executable, "-m", "tests.portal.apps.sample_app", "--role=rx", "--example_config"],
                         cwd=REPO, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    text = out.stdout
    assert "interprocess {" in text and "platform: \"default_goby_platform\"" in text
    assert "role: \"echo\"" in text and "warp_factor: 1" in text


class FailsAfterConnecting(SingleThreadApplication):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)  # connects to the broker
        raise RuntimeError("configuration problem found late")


class ThreadFailsAfterConnecting(SimpleThread):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.interprocess().subscribe("x", Sample, lambda m: None)
        raise RuntimeError("late failure")


class LaunchesFailingThread(MultiThreadApplication):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.launch_thread(ThreadFailsAfterConnecting)


@pytest.mark.parametrize("app_class", [FailsAfterConnecting, LaunchesFailingThread])
def test_constructor_failing_after_connecting_does_not_hang_shutdown(broker: BrokerProcess, app_class: type) -> None:
    cfg = SampleAppConfig()
    cfg.interprocess.CopyFrom(broker.interprocess_config())
    with pytest.raises((RuntimeError, ThreadError), match="late"):
        with running_app(app_class, cfg):
            pass


class EarlyPublisher(SimpleThread):
    """Publishes from a launched thread while the process is still held by the manager."""

    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.held_at_publish = self.interprocess().hold_state()
        for a in range(1, 4):
            self.interprocess().publish("early", Sample(a=a))


class EarlyApp(MultiThreadApplication):
    def __init__(self, cfg: SampleAppConfig) -> None:
        super().__init__(cfg)
        self.publisher = self.launch_thread(EarlyPublisher)


def test_publications_of_a_launched_thread_wait_for_the_hold(tmp_path: Path) -> None:
    from gateway.goby.portal.testing import broker_process

    hold = ["--hold", 'required_client: "early_app" required_client: "early_rx"']
    with broker_process(tmp_path, platform="early", extra_args=hold) as broker, \
            PortalClient(broker.interprocess_config(), "early_rx") as rx:
        got = rx.collect("early", Sample)
        cfg = SampleAppConfig()
        cfg.app.name = "early_app"
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        with running_app(EarlyApp, cfg) as app:
            assert app.publisher.held_at_publish is True
            assert rx.poll_until(lambda: len(got) == 3, 30)
    assert [m.a for m in got] == [1, 2, 3]


def test_a_thread_that_outlives_the_join_timeout_stays_listed_for_a_later_join() -> None:
    release = threading.Event()
    with running_app(InterthreadOnly, no_interprocess_cfg()) as app:
        worker = app.launch_thread(Worker, SampleAppConfig())
        started = threading.Event()
        worker.call_soon(lambda: (started.set(), release.wait(30)))  # busy: cannot see quit() yet
        assert started.wait(10)
        assert app.join_thread(Worker, timeout=0.2) == 0
        assert app.threads() == [worker]  # not forgotten
        release.set()
        assert app.join_thread(Worker, timeout=10) == 1
        assert app.threads() == []


def test_application_announces_its_configuration_on_goby_configuration(broker: BrokerProcess) -> None:
    # Goby3's SingleThreadApplication/MultiThreadApplication constructors publish app_cfg() on goby::configuration
    cfg = SampleAppConfig(count=42)
    cfg.app.name = "announcer"
    cfg.interprocess.CopyFrom(broker.interprocess_config())
    with PortalClient(broker.interprocess_config(), "cfg_listener") as client:
        announced = client.collect("goby::configuration", SampleAppConfig)
        assert client.wait_subscribed()
        with running_app(PortalApp, cfg) as app:
            assert client.poll_until(lambda: bool(announced))
    assert announced[0] == app.cfg() and announced[0].count == 42 and announced[0].app.name == "announcer"
    entries = {(e.direction, e.group, e.scheme, e.type, e.thread) for e in app.context.registry.entries()}
    assert ("publish", "goby::configuration", "PROTOBUF", "goby.test.zeromq.protobuf.SampleAppConfig",
            "PortalApp") in entries
