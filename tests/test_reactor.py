"""util.reactor: one poll for sockets, descriptors, timers and posts; idle means asleep."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import time

import pytest
import zmq

from util.reactor import Reactor, ReactorClosedError


@pytest.fixture()
def reactor():
    r = Reactor("test")
    yield r
    r.close()


def test_post_from_another_thread_wakes_a_blocked_poll(reactor: Reactor) -> None:
    ran: list[int] = []
    poster = threading.Timer(0.05, lambda: reactor.post(lambda: ran.append(threading.get_ident())))
    poster.start()
    started = time.monotonic()
    reactor.run_once(timeout_s=5.0)
    poster.join()
    assert ran == [threading.get_ident()]  # ran on the reactor's thread, not the poster's
    assert time.monotonic() - started < 1.0


def test_a_reader_runs_on_data_and_only_then(reactor: Reactor) -> None:
    a, b = socket.socketpair()
    got: list[bytes] = []
    reactor.add_reader(a, lambda: got.append(a.recv(100)))
    assert reactor.run_once(timeout_s=0.02) == 0
    b.send(b"hi")
    reactor.run_once(timeout_s=1.0)
    assert got == [b"hi"]
    reactor.remove_reader(a)
    b.send(b"again")
    assert reactor.run_once(timeout_s=0.02) == 0
    a.close()
    b.close()


def test_zmq_sockets_and_raw_descriptors_share_the_poll(reactor: Reactor) -> None:
    ctx = zmq.Context.instance()
    pull = ctx.socket(zmq.PULL)
    port = pull.bind_to_random_port("tcp://127.0.0.1")
    push = ctx.socket(zmq.PUSH)
    push.connect(f"tcp://127.0.0.1:{port}")
    r, w = os.pipe()
    got: list[object] = []
    reactor.add_reader(pull, lambda: got.append(pull.recv(zmq.NOBLOCK)))
    reactor.add_reader(r, lambda: got.append(os.read(r, 10)))
    push.send(b"zmq")
    os.write(w, b"fd")
    deadline = time.monotonic() + 2
    while len(got) < 2 and time.monotonic() < deadline:
        reactor.run_once(timeout_s=0.5)
    assert sorted(got) == [b"fd", b"zmq"]  # type: ignore[type-var]
    reactor.remove_reader(pull)
    reactor.remove_reader(r)
    push.close(0)
    pull.close(0)
    os.close(r)
    os.close(w)


def test_a_writer_runs_while_writable_until_removed(reactor: Reactor) -> None:
    a, b = socket.socketpair()
    calls = 0

    def flush() -> None:
        nonlocal calls
        calls += 1
        a.send(b"x")
        reactor.remove_writer(a)

    reactor.add_writer(a, flush)
    reactor.run_once(timeout_s=1.0)
    reactor.run_once(timeout_s=0.02)
    assert calls == 1
    assert b.recv(10) == b"x"
    a.close()
    b.close()


def test_periodic_timer_ticks_at_its_rate_and_sleeps_between(reactor: Reactor) -> None:
    ticks: list[float] = []
    reactor.call_every(0.02, lambda: ticks.append(time.monotonic()))
    deadline = time.monotonic() + 0.25
    iterations = 0
    while time.monotonic() < deadline:
        reactor.run_once(timeout_s=1.0)
        iterations += 1
    assert 9 <= len(ticks) <= 14
    # the poll slept until each tick: no spinning between them
    assert iterations <= len(ticks) + 3


def test_period_function_is_read_each_tick_and_a_cancelled_timer_never_fires(reactor: Reactor) -> None:
    period = [0.01]
    ticks: list[float] = []
    timer = reactor.call_every(lambda: period[0], lambda: ticks.append(time.monotonic()))
    once: list[int] = []
    cancelled = reactor.call_later(0.01, lambda: once.append(1))
    cancelled.cancel()
    end = time.monotonic() + 0.1
    while time.monotonic() < end:
        reactor.run_once(timeout_s=0.2)
    fast = len(ticks)
    period[0] = 0.05
    end = time.monotonic() + 0.2
    while time.monotonic() < end:
        reactor.run_once(timeout_s=0.2)
    slow = len(ticks) - fast
    assert fast >= 6 and slow <= 6
    assert once == []
    timer.cancel()
    assert reactor.next_deadline() is None


def test_a_timer_behind_schedule_skips_rather_than_bursts(reactor: Reactor) -> None:
    ticks: list[float] = []
    reactor.call_every(0.01, lambda: ticks.append(time.monotonic()))
    time.sleep(0.1)  # ten periods missed
    reactor.run_once(timeout_s=0.0)
    assert len(ticks) == 1


def test_a_failing_handler_is_logged_and_the_loop_goes_on(reactor: Reactor, caplog: pytest.LogCaptureFixture) -> None:
    ran: list[int] = []
    reactor.call_later(0.0, lambda: 1 / 0)
    reactor.post(lambda: ran.append(1))
    reactor.run_once(timeout_s=0.1)
    reactor.run_once(timeout_s=0.0)
    assert ran == [1]
    assert "ZeroDivisionError" in caplog.text


def test_stop_from_another_thread_ends_run_and_a_closed_reactor_refuses_posts() -> None:
    reactor = Reactor("stopping")
    stopper = threading.Timer(0.05, reactor.stop)
    stopper.start()
    reactor.run()
    stopper.join()
    reactor.close()
    with pytest.raises(ReactorClosedError, match="stopping"):
        reactor.post(print)


def test_an_idle_reactor_uses_no_cpu(reactor: Reactor) -> None:
    reactor.call_every(0.5, lambda: None)
    before = time.thread_time()
    end = time.monotonic() + 0.3
    while time.monotonic() < end:
        reactor.run_once()
    assert time.thread_time() - before < 0.02


def test_a_timer_weeks_away_does_not_overflow_the_poll(reactor: Reactor) -> None:
    reactor.call_later(60 * 86400.0, lambda: None)
    reactor.post(lambda: None)
    assert reactor.run_once() == 1  # the posted work ran; the far timer did not break the poll
    reactor.wake()
    reactor.run_once()


def test_a_zmq_socket_added_after_descriptors_keeps_them_watched(reactor: Reactor) -> None:
    a, b = socket.socketpair()
    got: list[bytes] = []
    reactor.add_reader(a, lambda: got.append(a.recv(10)))
    ctx = zmq.Context.instance()
    pull = ctx.socket(zmq.PULL)
    port = pull.bind_to_random_port("tcp://127.0.0.1")
    push = ctx.socket(zmq.PUSH)
    push.connect(f"tcp://127.0.0.1:{port}")
    reactor.add_reader(pull, lambda: got.append(pull.recv(zmq.NOBLOCK)))  # the poller changes kind here
    b.send(b"fd")
    push.send(b"zmq")
    deadline = time.monotonic() + 2
    while len(got) < 2 and time.monotonic() < deadline:
        reactor.run_once(timeout_s=0.5)
    assert sorted(got) == [b"fd", b"zmq"]
    reactor.remove_reader(pull)
    reactor.remove_reader(a)
    push.close(0)
    pull.close(0)
    a.close()
    b.close()


def test_a_reactor_on_plain_sockets_does_not_import_zmq() -> None:
    """pyzmq costs 2.4 MiB of private memory; the MOOS processes and the simulator have no ZeroMQ socket."""
    code = (
        "import socket, sys\n"
        "from util.reactor import Reactor\n"
        "r = Reactor('plain'); a, b = socket.socketpair(); got = []\n"
        "r.add_reader(a, lambda: got.append(a.recv(9))); b.send(b'x'); r.call_later(0.0, lambda: None)\n"
        "r.run_once(1.0); r.close()\n"
        "assert got == [b'x'], got\n"
        "print('zmq' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "False"
