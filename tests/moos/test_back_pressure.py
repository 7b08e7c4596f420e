"""A sender that outruns the link is slowed down (notify blocks), never dropped quietly."""

from __future__ import annotations

import threading
import time

from moos_doubles import StallingDBDouble

from gateway.moos import comms
from util.process import wait_until
from util.reactor import Reactor


def test_notify_blocks_when_the_link_is_full_and_loses_nothing() -> None:
    db = StallingDBDouble()
    client = comms()
    client.set_outbox_limit(50)
    payload = "p" * 32_000
    count = 1000  # 32 MB: more than loopback's socket buffers can hold
    done = threading.Event()

    def publish() -> None:
        for i in range(count):
            assert client.notify("BIG", f"{i}:{payload}")
        done.set()

    try:
        client.run("127.0.0.1", db.port, "hasty")
        assert client.wait_until_connected(10_000)
        publisher = threading.Thread(target=publish, name="hasty-publisher")
        publisher.start()
        # The DB reads nothing: kernel buffers fill, the writes block, then notify() itself blocks.
        assert not done.wait(1.5)
        stalled_at = client.get_number_messages_sent()
        assert client.get_number_of_unsent_messages() <= 50
        assert not done.wait(0.5) and client.get_number_messages_sent() == stalled_at
        db.resume()
        assert done.wait(30)
        publisher.join(10)
        wait_until(lambda: len(db.received) >= count, 30, "len(db.received) >= count")
        assert [int(m.string().split(":", 1)[0]) for m in db.received] == list(range(count))
    finally:
        client.close(False)
        db.close()


def test_notify_on_the_clients_own_reactor_thread_writes_through_and_loses_nothing() -> None:
    """On the reactor that serves the client (``comms(reactor=r)``), which cannot wait for itself, a sender that
    outruns the link is held in ``notify`` while it writes the packets out itself."""
    db = StallingDBDouble()
    reactor = Reactor("owner")
    runner = threading.Thread(target=reactor.run, name="owner")
    runner.start()
    client = comms(reactor=reactor)
    client.set_outbox_limit(50)
    payload = "p" * 32_000
    count = 1000
    done = threading.Event()

    def publish() -> None:
        for i in range(count):
            assert client.notify("BIG", f"{i}:{payload}")
        done.set()

    try:
        client.run("127.0.0.1", db.port, "hasty")
        assert client.wait_until_connected(10_000)
        reactor.post(publish)
        assert not done.wait(1.5)  # the owner's thread is held: the DB reads nothing
        assert client.get_number_of_unsent_messages() <= 50
        db.resume()
        assert done.wait(30)
        wait_until(lambda: len(db.received) >= count, 30, "len(db.received) >= count")
        assert [int(m.string().split(":", 1)[0]) for m in db.received] == list(range(count))
    finally:
        client.close(False)
        reactor.stop()
        runner.join(10)
        reactor.close()
        db.close()


def test_a_full_inbox_pauses_reading_until_fetch_catches_up(our_db) -> None:  # type: ignore[no-untyped-def]
    """A reader that does not fetch is not flooded: past ``set_inbox_limit`` the client stops reading (the bytes
    wait in the kernel and in the DB's outbox for it), and resumes when ``fetch()`` makes room; nothing is lost."""
    from gateway.moos.testing import collect_mail, connected_comms

    with connected_comms(our_db.port, "slow", ["FLOOD"]) as reader, connected_comms(our_db.port, "fast") as writer:
        reader.set_inbox_limit(100)
        for i in range(2000):  # in packets of about 100 (a packet is delivered whole, however big)
            assert writer.notify("FLOOD", f"{i}:" + "f" * 1000)
            if i % 100 == 99:
                time.sleep(0.02)
        wait_until(lambda: reader.get_number_of_unread_messages() >= 100, 10, "the inbox to fill")
        time.sleep(0.5)  # the writer's 2 MB have reached the DB; the reader's kernel buffers are full
        assert reader.get_number_of_unread_messages() < 2000  # it stopped reading
        got = collect_mail(reader, ["FLOOD"], until=2000, timeout=30)
        assert [int(m.string().split(":", 1)[0]) for m in got] == list(range(2000))
        assert not our_db.dropped
