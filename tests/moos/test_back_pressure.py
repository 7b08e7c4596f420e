"""A sender that outruns the link is slowed down (notify blocks), never dropped quietly."""

from __future__ import annotations

import socket
import threading

from gateway.moos import comms
from gateway.moos.codec import PROTOCOL_STRING_SIZE, PacketReader, encode_packet
from gateway.moos.message import DOUBLE, NOTIFY, WELCOME, MoosMessage
from util.process import wait_until


class StallingDBDouble:
    """Test double of a DB: handshakes like MOOSDB, then reads nothing until ``resume()``."""

    def __init__(self) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.resumed = threading.Event()
        self.received: list[MoosMessage] = []
        self.thread = threading.Thread(target=self._serve, name="stalling-db-double", daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        conn, _ = self.listener.accept()
        with conn:
            reader = PacketReader()
            data = b""
            while len(data) < PROTOCOL_STRING_SIZE:
                data += conn.recv(PROTOCOL_STRING_SIZE - len(data))
            while not reader.feed(conn.recv(4096)):
                pass
            welcome = MoosMessage(WELCOME, DOUBLE, community=b"double", msg_time=1.0, dval=0.0, sval=b"asynchronous")
            conn.sendall(encode_packet([welcome]))
            self.resumed.wait(30)
            conn.settimeout(10)
            while True:
                try:
                    chunk = conn.recv(1 << 16)
                except OSError:
                    return
                if not chunk:
                    return
                for packet in reader.feed(chunk):
                    self.received.extend(m for m in packet if m.msg_type == NOTIFY)

    def resume(self) -> None:
        self.resumed.set()

    def close(self) -> None:
        self.resumed.set()
        self.listener.close()
        self.thread.join(15)


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
