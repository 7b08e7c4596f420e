"""Test doubles of a MOOSDB for the client's tests: one that stops reading, one that records what it is sent."""

from __future__ import annotations

import socket
import threading
import time

from gateway.moos.codec import PROTOCOL_STRING_SIZE, PacketReader, encode_packet
from gateway.moos.message import DOUBLE, NOTIFY, TIMING, WELCOME, MoosMessage


def _handshake(conn: socket.socket, reader: PacketReader) -> None:
    """Read the protocol string and the client's name; answer WELCOME as MOOSDB does."""
    data = b""
    while len(data) < PROTOCOL_STRING_SIZE:
        data += conn.recv(PROTOCOL_STRING_SIZE - len(data))
    while not reader.feed(conn.recv(4096)):
        pass
    welcome = MoosMessage(WELCOME, DOUBLE, community=b"double", msg_time=1.0, dval=0.0, sval=b"asynchronous")
    conn.sendall(encode_packet([welcome]))


class StallingDBDouble:
    """Handshakes like MOOSDB, then reads nothing until ``resume()``; keeps the notifications it then reads."""

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
            _handshake(conn, reader)
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


class RecordingDBDouble:
    """Handshakes like MOOSDB, records every packet, and echoes a leading timing message after ``echo_delay``
    seconds (None: never), as MOOSDB confirms a processed packet."""

    def __init__(self, echo_delay: float | None = 0.0) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.echo_delay = echo_delay
        self.packets: list[list[MoosMessage]] = []
        self.lock = threading.Lock()
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._serve, name="recording-db-double", daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        self.listener.settimeout(10)
        try:
            conn, _ = self.listener.accept()
        except OSError:
            return
        with conn:
            reader = PacketReader()
            _handshake(conn, reader)
            conn.settimeout(0.05)
            echoes: list[tuple[float, bytes]] = []
            while not self._stop.is_set():
                now = time.monotonic()
                while echoes and echoes[0][0] <= now:
                    conn.sendall(echoes.pop(0)[1])
                try:
                    chunk = conn.recv(1 << 16)
                except TimeoutError:
                    continue
                except OSError:
                    return
                if not chunk:
                    return
                for packet in reader.feed(chunk):
                    with self.lock:
                        self.packets.append(packet)
                    if packet and packet[0].msg_type == TIMING and self.echo_delay is not None:
                        echo = packet[0]
                        echo.dval = echo.msg_time
                        echoes.append((time.monotonic() + self.echo_delay, encode_packet([echo])))

    def notifications(self) -> list[MoosMessage]:
        with self.lock:
            return [m for packet in self.packets for m in packet if m.msg_type == NOTIFY]

    def recorded(self) -> list[list[MoosMessage]]:
        with self.lock:
            return list(self.packets)

    def close(self) -> None:
        self._stop.set()
        self.listener.close()
        self.thread.join(15)
