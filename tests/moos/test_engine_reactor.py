"""The client on a reactor: ``comms(reactor=r)`` (no thread of its own), what never blocks the reactor's thread, and
the timing messages that confirm packets (docs/moos.md "Threads" and "Restarts")."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest
from moos_doubles import RecordingDBDouble

from gateway.moos import MoosClock, MoosError, MoosMessage, comms
from gateway.moos.engine import CONFIRM_INTERVAL_S
from gateway.moos.message import NOTIFY, SERVER_REQUEST, TIMING
from gateway.moos.server import MoosDB
from gateway.moos.testing import collect_mail, connected_comms
from util.process import wait_until
from util.reactor import Reactor


@pytest.fixture
def running_reactor() -> Iterator[Reactor]:
    """A reactor run by a thread named ``owner`` (a translator's or the helm's thread)."""
    reactor = Reactor("owner")
    runner = threading.Thread(target=reactor.run, name="owner")
    runner.start()
    try:
        yield reactor
    finally:
        reactor.stop()
        runner.join(10)
        reactor.close()


def on_reactor(reactor: Reactor, fn):  # type: ignore[no-untyped-def]
    """Run ``fn()`` on the reactor's thread; its result, or the exception it raised."""
    done = threading.Event()
    out: list[object] = []

    def call() -> None:
        try:
            out.append(fn())
        except Exception as exc:  # noqa: BLE001 - handed to the test
            out.append(exc)
        done.set()

    reactor.post(call)
    assert done.wait(10)
    return out[0]


def test_reactor_knows_its_owner_thread() -> None:
    reactor = Reactor("r")
    try:
        assert reactor.in_owner_thread()  # its creator, until another thread runs it
        seen: list[bool] = []
        other = threading.Thread(target=lambda: (reactor.run_once(0), seen.append(reactor.in_owner_thread())))
        other.start()
        other.join(10)
        assert seen == [True] and not reactor.in_owner_thread()
    finally:
        reactor.close()


def test_a_client_on_a_given_reactor_runs_every_callback_there_and_has_no_thread(
        our_db: MoosDB, running_reactor: Reactor) -> None:
    seen: dict[str, str] = {}
    got: list[float] = []
    client = comms(clock=MoosClock(), reactor=running_reactor)

    def on_connect() -> None:
        seen["connect"] = threading.current_thread().name
        client.register("RV", 0)
        client.register("RQ", 0)

    def on_mail() -> None:
        seen["mail"] = threading.current_thread().name
        got.extend(m.double() for m in client.fetch() if m.key() == "RV")

    def on_queue(msg: MoosMessage) -> None:
        seen["queue"] = threading.current_thread().name
        got.append(-msg.double())

    client.set_on_connect_callback(on_connect)
    client.set_on_mail_callback(on_mail)
    client.add_active_queue("q", on_queue)
    client.add_message_route_to_active_queue("q", "RQ")
    before = {t.name for t in threading.enumerate()}
    assert client.run("127.0.0.1", our_db.port, "guest")  # returns at once: r's thread connects
    try:
        assert client.wait_until_connected(10_000)  # from another thread: waits as usual
        assert not any("guest" in t.name for t in threading.enumerate() if t.name not in before)
        # on r's thread nothing waits for the DB: connected now, so True; a request raises at once
        assert on_reactor(running_reactor, lambda: client.wait_until_connected(5_000)) is True
        assert isinstance(on_reactor(running_reactor, lambda: client.server_request("ALL")), MoosError)
        with connected_comms(our_db.port, "host", ["BACK"]) as host:
            wait_until(lambda: all(k in our_db.db.vars and b"guest" in our_db.db.vars[k].subscribers
                                   for k in (b"RV", b"RQ")), 10, "guest's registrations")
            host.notify("RV", 1.0)
            host.notify("RQ", 2.0)
            wait_until(lambda: sorted(got) == [-2.0, 1.0], 10, "RV and RQ")
            assert on_reactor(running_reactor, lambda: client.notify("BACK", 3.0)) is True  # from r's thread
            assert client.notify("BACK", 4.0)  # and from another
            assert [m.double() for m in collect_mail(host, ["BACK"], until=2)] == [3.0, 4.0]
        assert seen == {"connect": "owner", "mail": "owner", "queue": "owner"}
    finally:
        client.close(True)
    assert client.get_number_of_undelivered_messages() == 0


def test_on_the_reactors_own_thread_waiting_for_the_db_raises_instead_of_blocking(our_db: MoosDB) -> None:
    reactor = Reactor("mine")  # created here: this thread owns it, and nothing runs it yet
    client = comms(clock=MoosClock(), reactor=reactor)
    try:
        client.run("127.0.0.1", our_db.port, "selfish")
        with pytest.raises(MoosError, match="would block the thread that connects it"):
            client.wait_until_connected(100)
        assert client.wait_until_connected(0) is False
        deadline = time.monotonic() + 10
        while not client.is_connected() and time.monotonic() < deadline:
            reactor.run_once(0.1)  # this thread connects it, as the owner's loop would
        assert client.wait_until_connected(100) is True
        assert client.notify("MINE", 1.0)
        client.close(True)  # on the reactor's thread: writes out and waits for the DB's confirmation here
        assert client.get_number_of_undelivered_messages() == 0
        assert b"MINE" in our_db.db.vars and our_db.db.vars[b"MINE"].dval == 1.0
    finally:
        client.close(False)
        reactor.close()


def test_close_waits_for_the_dbs_confirmation() -> None:
    db = RecordingDBDouble(echo_delay=0.5)
    client = comms(clock=MoosClock())
    undelivered: list[MoosMessage] = []
    client.set_on_undelivered_callback(undelivered.extend)
    try:
        client.run("127.0.0.1", db.port, "patient")
        assert client.wait_until_connected(10_000)
        for i in range(10):
            assert client.notify("SEQ", float(i))
        client.close(True)
        assert undelivered == [] and client.get_number_of_undelivered_messages() == 0
        assert [m.double() for m in db.notifications()] == [float(i) for i in range(10)]
    finally:
        db.close()


def test_close_reports_what_the_db_never_confirmed() -> None:
    db = RecordingDBDouble(echo_delay=None)
    client = comms(clock=MoosClock())
    undelivered: list[MoosMessage] = []
    client.set_on_undelivered_callback(undelivered.extend)
    try:
        client.run("127.0.0.1", db.port, "doubtful")
        assert client.wait_until_connected(10_000)
        for i in range(5):
            assert client.notify("SEQ", float(i))
        client.close(True)
        assert [m.double() for m in undelivered if m.key() == "SEQ"] == [0.0, 1.0, 2.0, 3.0, 4.0]
        assert client.get_number_of_undelivered_messages() == len(undelivered)
    finally:
        db.close()


def test_a_lone_post_asks_for_confirmation_and_a_stream_about_once_per_interval() -> None:
    db = RecordingDBDouble()
    client = comms(clock=MoosClock())
    try:
        client.run("127.0.0.1", db.port, "poster")
        assert client.wait_until_connected(10_000)
        time.sleep(2 * CONFIRM_INTERVAL_S)
        assert client.notify("LONE", 1.0)
        wait_until(lambda: any(m.key() == "LONE" for m in db.notifications()), 10, "LONE")
        (lone,) = [p for p in db.recorded() if any(m.key() == "LONE" for m in p)]
        assert lone[0].msg_type == TIMING  # confirmed on its own
        started = time.monotonic()
        for i in range(60):  # a steady stream, a packet each: confirmation is asked about once per interval
            client.notify("STREAM", float(i))
            time.sleep(0.01)
        wait_until(lambda: sum(m.key() == "STREAM" for m in db.notifications()) == 60, 10, "the stream")
        elapsed = time.monotonic() - started
        stream = [p for p in db.recorded() if any(m.key() == "STREAM" for m in p)]
        asked = sum(p[0].msg_type == TIMING for p in stream)
        assert len(stream) >= 30 and asked <= elapsed / CONFIRM_INTERVAL_S + 2, (asked, len(stream), elapsed)
    finally:
        client.close(False)
        db.close()


def test_a_publisher_asks_who_subscribes_with_its_first_publication_then_in_its_timing_packet() -> None:
    db = RecordingDBDouble()
    client = comms(clock=MoosClock())
    try:
        client.run("127.0.0.1", db.port, "publisher")
        assert client.wait_until_connected(10_000)
        assert client.notify("OUT", 1.0)
        wait_until(lambda: sum(_asks(p) for p in db.recorded()) >= 2, 10, "two PROC_SUMMARY requests")
        asking = [p for p in db.recorded() if _asks(p)]
        # the first rides the packet of the first publication of OUT (its subscribers must be known from the start),
        # the next ones the once-a-second timing packet: never a packet or a wake-up of their own
        assert any(m.msg_type == NOTIFY and m.raw_key == b"OUT" for m in asking[0])
        assert all(p[0].msg_type == TIMING for p in asking[1:])
    finally:
        client.close(False)
        db.close()


def _asks(packet: list[MoosMessage]) -> bool:
    return any(m.msg_type == SERVER_REQUEST and m.raw_key == b"PROC_SUMMARY" for m in packet)


def test_the_db_is_sent_our_community_so_it_forwards_runs_as_received(our_db: MoosDB) -> None:
    """Our client stamps the community from the WELCOME; the DB forwards a run of notifications without
    re-encoding them, and what arrives is what MOOSDB would send (community, source, values, order)."""
    with connected_comms(our_db.port, "sub", ["RUN"]) as sub, connected_comms(our_db.port, "pub") as pub:
        for i in range(500):
            pub.notify("RUN", float(i))
        got = collect_mail(sub, ["RUN"], until=500)
    assert [m.double() for m in got] == [float(i) for i in range(500)]
    assert {(m.community(), m.source(), m.msg_type) for m in got} == {("moos", "pub", NOTIFY)}
