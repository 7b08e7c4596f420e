"""``MoosDB``: a MOOSDB-compatible server on one reactor thread (``util.reactor``).

One thread accepts, handshakes, reads, runs the database and writes, so packets from all clients are
processed one at a time in arrival order (as the C++ central server thread does) without locks. Sockets are
non-blocking readers of the reactor, and reads are never paused: a slow reader is handled alone. Each connection
has its own bounded outbox (``max_outbox_bytes``), written by the reactor when the socket takes bytes again
(``add_writer``); a client whose outbox overflows, or that takes nothing for ``stall_timeout`` seconds while mail
waits, is dropped and named (MOOSDB gives each client its own writer thread for the same reason, see docs/moos.md
"Slow clients and memory"). Input is bounded per connection by ``max_packet_bytes`` (a partial packet cannot grow
past it) and all buffered input and output together by ``max_buffered_bytes``: past it, the connection holding the
most is dropped and named. Any client that sends bad bytes is dropped alone, with the reason logged; the others
carry on. A connection's state and the timeouts that drop it are in ``server_client.py``; the DB's logic, free of
sockets, in ``database.py``, its hot path over a packet's bytes in ``db_wire.py``.

Nothing polls: the mail a read made is pushed when the read is processed, work over every variable runs a slice
per reactor round while it lasts (a zero-delay timer), and the timeouts are one timer set for the earliest moment
any client could time out. A client that looks silent is first checked for bytes waiting in the kernel: when the DB
itself was busy (a big request, a stalled machine), what a client sent meanwhile is not blamed on it.
A second connection with a connected client's name is refused (POISON, as MOOSDB), naming the address that holds
the name, unless that holder has been silent for half the client timeout: then it is presumed dead (a
half-open socket after a network drop or a DB restart) and replaced, so the real client is not locked out.
"""

from __future__ import annotations

import logging
import select
import socket
import threading
import time as _time

from util.memory import release_freed_memory
from util.reactor import Reactor, Timer
from util.sockets import accept_client

from .clock import MoosClock
from .codec import (
    DEFAULT_MAX_PACKET_BYTES,
    PACKET_HEADER_SIZE,
    PROTOCOL_STRING,
    PROTOCOL_STRING_SIZE,
    PacketReader,
    decode_message,
    decode_packet_body,
    encode_message,
    frame_packet,
    packet_count,
)
from .database import MoosDatabase
from .db_jobs import JOB_SLICE_S
from .db_limits import MAX_NAME_BYTES, MAX_STORED_BYTES, MAX_VARIABLES, MAX_VARIABLES_PER_CLIENT, preview
from .db_wire import process_wire
from .errors import MoosError, ProtocolError
from .message import (
    ASYNC_KEY,
    DATA,
    DOUBLE,
    NULL_MSG,
    POISON,
    STRING,
    TIMING,
    WELCOME,
    MoosMessage,
    to_bytes,
    to_str,
)
from .server_client import CLOSED, HELLO, PROTOCOL, READY, ServerClient, deadline, timeout_reason
from .wildcard import wild_match

log = logging.getLogger(__name__)

HANDSHAKE_TIMEOUT_S = 5.0
RECV_BYTES = 256 * 1024
MAX_OUTBOX_BYTES = 16 * 1024 * 1024
MAX_BUFFERED_BYTES = 256 * 1024 * 1024
SEND_CHUNK = 1024 * 1024
TRIM_AFTER_BYTES = 64 * 1024
TIMING_TYPE_OFFSET = PACKET_HEADER_SIZE + 8  # a packet's first message's type byte (after its length and id)


class MoosDB:
    """A MOOSDB. ``start()`` binds (``port=0`` picks a free port, see ``.port``) and serves on a thread."""

    def __init__(
        self,
        host: str = "127.0.0.1",
        port: int = 0,
        community: str = "moos",
        time_warp: float = 1.0,
        client_timeout: float = 5.0,
        max_packet_bytes: int = DEFAULT_MAX_PACKET_BYTES,
        stall_timeout: float = 6.0,
        handshake_timeout: float = HANDSHAKE_TIMEOUT_S,
        max_outbox_bytes: int = MAX_OUTBOX_BYTES,
        max_buffered_bytes: int = MAX_BUFFERED_BYTES,
        response: dict[str, float] | None = None,
        max_variables: int = MAX_VARIABLES,
        max_variables_per_client: int = MAX_VARIABLES_PER_CLIENT,
        max_name_bytes: int = MAX_NAME_BYTES,
        max_stored_bytes: int = MAX_STORED_BYTES,
    ) -> None:
        self.host = host
        self._requested_port = int(port)
        self.community = community
        self.clock = MoosClock(time_warp)
        self.client_timeout = float(client_timeout)
        self.stall_timeout = float(stall_timeout)
        self.handshake_timeout = float(handshake_timeout)
        self.max_outbox_bytes = int(max_outbox_bytes)
        self.max_buffered_bytes = int(max_buffered_bytes)
        self.buffered_bytes = 0  # input + output held for all connections
        self._trim_due = False  # a big buffer was freed: give the memory back at the end of the round
        # MOOSDB's --response: client name or wildcard pattern -> seconds asked between the client's writes
        self.response = {to_bytes(k): float(v) for k, v in (response or {}).items()}
        self.max_packet_bytes = max_packet_bytes
        self.db = MoosDatabase(community, self.clock, max_variables=max_variables,
                               max_variables_per_client=max_variables_per_client, max_name_bytes=max_name_bytes,
                               max_stored_bytes=max_stored_bytes)
        self.max_name_bytes = int(max_name_bytes)
        self._hostname = to_bytes(socket.gethostname())
        self._listener: socket.socket | None = None
        self._reactor: Reactor | None = None
        self._thread: threading.Thread | None = None
        self._clients: dict[int, ServerClient] = {}
        self._by_name: dict[bytes, ServerClient] = {}
        self._lock = threading.Lock()
        self._recv_buf = bytearray(RECV_BYTES)
        self._recv_view = memoryview(self._recv_buf)
        self._round_timer: Timer | None = None  # end of the current round of reads: push mail, run jobs
        self._round_due = False
        self._timeout_timer: Timer | None = None
        self.port = 0
        self.dropped: list[tuple[str, str]] = []  # (client, reason) for every client dropped for a fault

    # ---- lifecycle ---------------------------------------------------------------------------------
    def start(self) -> MoosDB:
        """Bind and start serving; returns self. Raises OSError if the port is taken."""
        if self._thread is not None:
            return self
        listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            listener.bind((self.host, self._requested_port))
            listener.listen(50)
        except OSError:
            listener.close()
            raise
        listener.setblocking(False)
        self._listener = listener
        self.port = listener.getsockname()[1]
        ready = threading.Event()
        self._thread = threading.Thread(target=self._run, args=(ready,), name=f"moosdb-{self.port}", daemon=True)
        self._thread.start()
        ready.wait()
        log.info("MOOSDB %s serving on %s:%d (warp %g)", self.community, self.host, self.port, self.clock.warp)
        return self

    def stop(self) -> None:
        """Close every connection and the listening socket, and end the thread; idempotent."""
        thread = self._thread
        if thread is None:
            return
        if self._reactor is not None:
            self._reactor.stop()
        if thread is not threading.current_thread():
            thread.join(10.0)
        self._thread = None

    def __enter__(self) -> MoosDB:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def serve_forever(self) -> None:
        """Block until :meth:`stop` is called from elsewhere (a signal handler, another thread).

        A plain join, not a polling one: a signal still runs its handler during it (lock waits are interruptible
        on POSIX), and nothing wakes on a period."""
        thread = self._thread
        if thread is not None:
            thread.join()

    @property
    def address(self) -> tuple[str, int]:
        return self.host, self.port

    def client_names(self) -> list[str]:
        """Names of the clients that completed the handshake, in connection order."""
        with self._lock:
            return [to_str(name) for name in self._by_name]

    # ---- the loop ----------------------------------------------------------------------------------
    def _run(self, ready: threading.Event) -> None:
        reactor = Reactor(f"moosdb-{self.port}")  # built on this thread, which owns it
        self._reactor = reactor
        assert self._listener is not None
        reactor.add_reader(self._listener, self._accept)
        self._round_timer = reactor.call_later(3600.0, self._end_of_round)
        self._round_timer.cancel()
        ready.set()
        try:
            reactor.run()
        except Exception:
            log.exception("MOOSDB I/O loop failed")
        finally:
            self._shutdown()
            reactor.close()

    def _shutdown(self) -> None:
        for client in list(self._clients.values()):
            self._close(client, None)
        if self._listener is not None:
            try:
                self._listener.close()
            except OSError:
                pass
        log.info("MOOSDB %s on port %d stopped", self.community, self.port)

    def _round_ends(self) -> None:
        """Run ``_end_of_round`` once after the handlers of this reactor round (a reused zero-delay timer)."""
        if not self._round_due:
            self._round_due = True
            assert self._round_timer is not None
            self._round_timer.reschedule(_time.monotonic())

    def _end_of_round(self) -> None:
        """After a round of reads: push held mail to async clients, advance jobs a slice, give memory back."""
        self._round_due = False
        db = self.db
        if db.jobs_pending:
            db.run_jobs(JOB_SLICE_S)
        self._push_waiting_mail()
        if db.jobs_pending:
            self._round_ends()  # the next slice after the next poll, so I/O goes on meanwhile
        if self._trim_due:
            self._trim_due = False
            release_freed_memory()

    def _accept(self) -> None:
        assert self._listener is not None
        accepted = accept_client(self._listener)
        if accepted is None:
            return
        sock, peer = accepted
        client = ServerClient(sock, peer, self.max_packet_bytes)
        self._clients[sock.fileno()] = client
        assert self._reactor is not None
        self._reactor.add_reader(sock, lambda: self._read(client))
        client.events = 1
        self._arm_timeouts(client.accepted + self.handshake_timeout)
        log.debug("accepted a connection from %s", client.peer)

    def _set_writer(self, client: ServerClient) -> None:
        """Watch the socket for room while output waits; stop once it is flushed."""
        want = 2 if client.out else 1
        if want == client.events or client.state == CLOSED:
            return
        assert self._reactor is not None
        if want == 2:
            self._reactor.add_writer(client.sock, lambda: self._flush(client))
        else:
            self._reactor.remove_writer(client.sock)
        client.events = want

    # ---- timeouts ----------------------------------------------------------------------------------
    def _arm_timeouts(self, when: float) -> None:
        """Make sure the timeout check runs by ``when``."""
        timer = self._timeout_timer
        if timer is not None and timer.active and timer.deadline <= when:
            return
        if timer is not None:
            timer.cancel()
        assert self._reactor is not None
        self._timeout_timer = self._reactor.call_at(when, self._check_timeouts)

    def _check_timeouts(self) -> None:
        """Drop the clients that timed out (not those whose bytes wait in the kernel); re-arm for the next."""
        self._timeout_timer = None
        now = _time.monotonic()
        due = [(c, r) for c in list(self._clients.values())
               if (r := timeout_reason(c, now, self.handshake_timeout, self.stall_timeout, self.client_timeout))]
        if due:
            # "not reading" is excused by room to write now; silence by bytes waiting to be read
            waiting = _ready_sockets([(c.sock, select.POLLOUT if r.startswith("not reading") else select.POLLIN)
                                      for c, r in due])
            for client, reason in due:
                if client.sock.fileno() in waiting:
                    client.last_rx = client.last_progress = now  # its bytes are there: the DB was the slow one
                else:
                    self._close(client, reason)
        self.db.flush_warnings()
        if self._clients:
            self._arm_timeouts(max(now + 0.01, min(deadline(c, self.handshake_timeout, self.stall_timeout,
                                                            self.client_timeout) for c in self._clients.values())))

    # ---- reading -----------------------------------------------------------------------------------
    def _read(self, client: ServerClient) -> None:
        try:
            n = client.sock.recv_into(self._recv_buf)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            self._close(client, f"read failed: {exc}", fault=False)
            return
        if not n:
            partial = client.reader.pending_bytes or (client.state == PROTOCOL and len(client.proto_buf))
            if partial:
                self._close(client, f"closed the connection in the middle of a packet ({partial} bytes unfinished)")
            else:
                self._close(client, "closed the connection", fault=False)
            return
        data = self._recv_view[:n]  # one reused buffer: a fresh 256 KiB bytes per recv would cost an mmap
        client.last_rx = _time.monotonic()
        if client.state == PROTOCOL:
            need = PROTOCOL_STRING_SIZE - len(client.proto_buf)
            client.proto_buf += bytes(data[:need])
            data = data[need:]
            if len(client.proto_buf) < PROTOCOL_STRING_SIZE:
                return
            offered = client.proto_buf.split(b"\0", 1)[0]
            if offered.lower() != PROTOCOL_STRING.lower():
                self._close(client, f"incompatible wire protocol: sent {offered[:40]!r}, expected {PROTOCOL_STRING!r}")
                return
            client.state = HELLO
            if not data:
                return
        try:
            packets = client.reader.feed_raw(data)
        except ProtocolError as exc:
            for region, pos, total in exc.packets:
                if client.state == CLOSED or not self._on_packet(client, region, pos, total):
                    break
            else:
                self._close(client, f"malformed packet: {exc}")
            self._end_read()
            return
        for region, pos, total in packets:
            if client.state == CLOSED or not self._on_packet(client, region, pos, total):
                break
        else:
            self._account(client)
        self._end_read()

    def _end_read(self) -> None:
        """After a read: push the mail it made (one packet per subscriber per read); jobs and trimming wait for the
        end of the round."""
        db = self.db
        if db.mail_waiting:
            self._push_waiting_mail()
        if db.jobs_pending or self._trim_due:
            self._round_ends()

    def _on_packet(self, client: ServerClient, region: bytes, pos: int, total: int) -> bool:
        try:
            if client.state == HELLO:
                return self._handshake(client, decode_packet_body(region, pos, total))
            self._process(client, region, pos, total)
        except ProtocolError as exc:
            self._close(client, f"malformed packet: {exc}")
            return False
        except MoosError as exc:
            self._close(client, str(exc))
            return False
        return client.state != CLOSED

    def _handshake(self, client: ServerClient, packet: list[MoosMessage]) -> bool:
        """The client's first packet names it: POISON a duplicate or empty name, else WELCOME."""
        if not packet:
            return self._poison(client, "Failed to read receive client's name")
        hello = packet[0]
        name = hello.raw_sval
        if hello.msg_type != DATA:
            return self._poison(client, f"expected a MOOS_DATA handshake message, got type {hello.type()!r}")
        if not name:
            return self._poison(client, "Failed to read receive client's name (empty)")
        if len(name) > self.max_name_bytes:
            return self._poison(client, f"client name {preview(name)} is longer than max_name_bytes "
                                f"({self.max_name_bytes})")
        holder = self._by_name.get(name)
        if holder is not None and not self._replace_stale(holder, client):
            log.warning("refusing a second client named %r from %s: that name is connected from %s (heard from "
                        "%.1f s ago)", to_str(name), client.peer, holder.peer, _time.monotonic() - holder.last_rx)
            return self._poison(client, f'A client of this name ("{to_str(name)}") already exists '
                                f"(connected from {holder.peer})")
        now = self.clock.time()
        welcome = MoosMessage(
            WELCOME, DOUBLE, aux=b"hostname=" + self._hostname, community=self.db.community,
            msg_time=now, dval=now - hello.msg_time, sval=ASYNC_KEY,
        )
        client.name = name
        client.asynchronous = hello.raw_key.lower() == ASYNC_KEY
        client.state = READY
        with self._lock:
            self._by_name[name] = client
        self._send(client, frame_packet([encode_message(welcome)]))
        self.db.connect(name, client.asynchronous)
        log.info("client %s connected (%s)", client.label(), "asynchronous" if client.asynchronous else "synchronous")
        return client.state != CLOSED

    def _replace_stale(self, holder: ServerClient, newcomer: ServerClient) -> bool:
        """Drop ``holder`` for ``newcomer`` if it has been silent for half the client timeout; True if dropped.

        A live client writes at least once a second (the async timing message, the sync poll), so such silence
        means a dead peer whose socket the DB has not noticed yet; refusing the newcomer would POISON the real
        client (fatal to libMOOS and to ours) and lock it out for good.
        """
        silent = _time.monotonic() - holder.last_rx
        if silent < self.client_timeout / 2 or _ready_sockets([(holder.sock, select.POLLIN)]):
            return False
        self._close(holder, f"replaced by a new connection of the same name from {newcomer.peer} after "
                    f"{silent:.1f} s of silence")
        return True

    def _poison(self, client: ServerClient, reason: str) -> bool:
        poison = MoosMessage(POISON, STRING, msg_time=self.clock.time(), sval=to_bytes(reason))
        self._send(client, frame_packet([encode_message(poison)]))
        self._flush(client)
        self._close(client, f"refused: {reason}")
        return False

    def _process(self, client: ServerClient, region: bytes, pos: int, total: int) -> None:
        """One packet through the DB, from its bytes; reply as the ThreadedCommServer does for sync and async
        clients (the timing message, when first, is echoed with the DB's time)."""
        db = self.db
        count = packet_count(region, pos, total)
        p, end = pos + PACKET_HEADER_SIZE, pos + total
        timing = None
        if count and region[pos + TIMING_TYPE_OFFSET] == TIMING[0]:
            timing, p = decode_message(region, p, end)
            count -= 1
            now_local = self.clock.local_time()
            db.record_timing(client.name, (now_local - timing.msg_time) * 1000.0 / self.clock.warp)
            timing.dval = now_local
            timing.dval2 = self._response_delay(client.name)
        replies, _ = process_wire(db, region, p, end, count, client.name)
        out: list[bytes] = []
        if not client.asynchronous:
            out.append(encode_message(MoosMessage(NULL_MSG, DOUBLE, dval=self.clock.local_time())))
        elif timing is not None:
            out.append(encode_message(timing))
        n = len(out)
        if count or not client.asynchronous:
            chunks, held = db.take_mail(client.name)
            out.extend(chunks)
            out.extend(encode_message(m) for m in replies)
            n += held + len(replies)
        if out:
            # Others' mail from this packet goes out before this reply: a client that sees its packet confirmed
            # (the echoed timing message or the sync reply) knows the mail already left the DB.
            self._push_waiting_mail()
            self._send(client, frame_packet(out, n))

    def _response_delay(self, name: bytes) -> float:
        """The write period this client was asked to keep (``--response``), told to it in ``T.val2``."""
        if not self.response:
            return 0.0
        if name in self.response:
            return self.response[name]
        for pattern, delay in self.response.items():
            if wild_match(pattern, name):
                return delay
        return 0.0

    def _push_waiting_mail(self) -> None:
        """Asynchronous clients get their held mail pushed without asking (sync clients wait for their poll)."""
        db = self.db
        if not db.mail_waiting:
            return
        for name in list(db.mail_waiting):
            client = self._by_name.get(name)
            if client is None:
                db.mail_waiting.discard(name)
            elif client.asynchronous:
                chunks, count = db.take_mail(name)
                if count:
                    self._send(client, frame_packet(chunks, count))

    # ---- writing -----------------------------------------------------------------------------------
    def _send(self, client: ServerClient, data: bytes) -> None:
        if client.state == CLOSED:
            return
        if not client.out:
            try:
                sent = client.sock.send(data)
            except (BlockingIOError, InterruptedError):
                sent = 0
            except OSError as exc:
                self._close(client, f"write failed: {exc}", fault=False)
                return
            if sent == len(data):
                return
            data = data[sent:]
            client.last_progress = _time.monotonic()
        client.out.append(data)
        client.out_bytes += len(data)
        if client.out_bytes > self.max_outbox_bytes:
            self._close(client, f"not keeping up: outbox full ({client.out_bytes} bytes unsent, "
                        f"limit {self.max_outbox_bytes})")
            return
        self._set_writer(client)
        self._account(client)

    def _flush(self, client: ServerClient) -> None:
        while client.out:
            chunk = client.out[0]
            if len(client.out) > 1 and len(chunk) < SEND_CHUNK:
                parts = []
                size = 0
                while client.out and size < SEND_CHUNK:
                    part = client.out.popleft()
                    parts.append(part)
                    size += len(part)
                chunk = b"".join(parts)
                client.out.appendleft(chunk)
            try:
                sent = client.sock.send(chunk)
            except (BlockingIOError, InterruptedError):
                break
            except OSError as exc:
                self._close(client, f"write failed: {exc}", fault=False)
                return
            client.last_progress = _time.monotonic()
            client.out_bytes -= sent
            if sent < len(chunk):
                client.out[0] = chunk[sent:]
                break
            client.out.popleft()
        self._set_writer(client)
        self._account(client)

    # ---- memory bounds -----------------------------------------------------------------------------
    def _account(self, client: ServerClient) -> None:
        """Update the total of buffered bytes with this client's; past ``max_buffered_bytes`` drop the biggest."""
        if client.state == CLOSED:
            return
        held = client.reader.pending_bytes + client.out_bytes
        self.buffered_bytes += held - client.held
        client.held = held
        while self.buffered_bytes > self.max_buffered_bytes and self._clients:
            biggest = max(self._clients.values(), key=lambda c: c.held)
            self._close(biggest, f"holds the most buffered data ({biggest.held} bytes) when all connections "
                        f"together passed max_buffered_bytes ({self.max_buffered_bytes})")

    # ---- closing -----------------------------------------------------------------------------------
    def _close(self, client: ServerClient, reason: str | None, fault: bool = True) -> None:
        if client.state == CLOSED:
            return
        was_ready = client.state == READY
        client.state = CLOSED
        if reason is not None:
            if fault:
                log.warning("dropping client %s: %s", client.label(), reason)
                self.dropped.append((client.label(), reason))
            else:
                log.info("client %s left: %s", client.label(), reason)
        if client.events and self._reactor is not None:
            self._reactor.remove_reader(client.sock)
            self._reactor.remove_writer(client.sock)
            client.events = 0
        self._clients.pop(client.sock.fileno(), None)
        try:
            client.sock.close()
        except OSError:
            pass
        self.buffered_bytes -= client.held
        self._trim_due |= client.held >= TRIM_AFTER_BYTES
        client.held = 0
        client.out.clear()
        client.out_bytes = 0
        client.reader = PacketReader(0)  # frees the partial packet now, not when the last reference goes
        if was_ready:
            with self._lock:
                if self._by_name.get(client.name) is client:
                    del self._by_name[client.name]
            self.db.disconnect(client.name)
            if self._round_timer is not None and self._reactor is not None and not self._reactor.closed:
                self._round_ends()  # DB_EVENT for the others


def _ready_sockets(socks: list[tuple[socket.socket, int]]) -> set[int]:
    """The descriptors among ``socks`` ready now for their event (POLLIN: bytes wait; POLLOUT: room to write)."""
    poller = select.poll()
    for sock, event in socks:
        poller.register(sock, event)
    try:
        return {fd for fd, ready in poller.poll(0) if ready & (select.POLLIN | select.POLLOUT)}
    except OSError:
        return set()
