"""Proof of issue #19 items 1-2 against the ``moos-db`` process: two good clients exchange 20,000 numbered
messages while slow readers and partial-packet senders attack. Nothing is lost or reordered, no gap between
good messages passes 200 ms, the attackers are dropped and named, and the DB's RSS stays within its
configured buffer cap plus a small constant."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

from gateway.moos.codec import PROTOCOL_BYTES, encode_packet
from gateway.moos.message import DATA, DOUBLE, NOTIFY, REGISTER, STRING, TIMING, MoosMessage
from gateway.moos.testing import connected_comms, moosdb_process
from util.process import wait_until

TOTAL_CAP = 8 * 1024 * 1024
OUTBOX_CAP = 1024 * 1024
PACKET_CAP = 4 * 1024 * 1024
PER_CLIENT = 10_000  # each good client sends this many: 20,000 exchanged
RSS_SLACK = 40 * 1024 * 1024  # interpreter heap growth, transient copies while decoding/encoding
HEAP_SLACK = 8 * 1024 * 1024  # what the interpreter's allocator keeps after 20,000 messages (seen: 1-8 MiB)
LEAK_SLACK = 4 * 1024 * 1024  # a second attack may fragment the heap a little, never by a cap's worth


def hello(name: str) -> bytes:
    msg = MoosMessage(DATA, STRING, key=b"asynchronous", msg_time=1.0, sval=name.encode())
    return PROTOCOL_BYTES + encode_packet([msg])


def rss(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    return 0


class Attack:
    """Raw-socket attackers on one thread (cheap: mostly sleeping): a firehose on BUSY, a new slow reader of
    BUSY every 0.3 s, and a partial-packet sender every 0.5 s that stops 90% into a 4 MB packet."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.stop = threading.Event()
        self.socks: list[socket.socket] = []
        self.slow = self.partial = 0
        self.thread = threading.Thread(target=self._run, name="attack", daemon=True)
        self._busy = encode_packet([MoosMessage(NOTIFY, STRING, src=b"hose", key=b"BUSY", msg_time=1.0,
                                                sval=b"b" * 60_000)])
        big = encode_packet([MoosMessage(NOTIFY, STRING, src=b"x", key=b"X", msg_time=1.0,
                                         sval=b"p" * (PACKET_CAP - 200))])
        self._partial = big[: int(len(big) * 0.9)]

    def _connect(self, name: str, rcvbuf: int | None = None) -> socket.socket | None:
        sock = socket.socket()
        if rcvbuf:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        try:
            sock.connect(("127.0.0.1", self.port))
            sock.sendall(hello(name))
        except OSError:
            sock.close()
            return None
        self.socks.append(sock)
        return sock

    def _run(self) -> None:
        hose = self._connect("hose")
        assert hose is not None
        hose.setblocking(False)
        tick = 0
        while not self.stop.wait(0.02):
            tick += 1
            try:
                hose.send(self._busy)  # ~3 MB/s; a partial send only delays the next packet's start
            except BlockingIOError:
                pass
            except OSError:
                return
            if tick % 15 == 0:
                self.slow += 1
                sock = self._connect(f"slow{self.slow}", rcvbuf=4096)
                if sock is not None:
                    reg = MoosMessage(REGISTER, DOUBLE, src=f"slow{self.slow}".encode(), key=b"BUSY", dval=0.0)
                    sock.sendall(encode_packet([reg]))
            if tick % 25 == 0:
                self.partial += 1
                sock = self._connect(f"partial{self.partial}")
                if sock is not None:
                    sock.setblocking(False)
                    try:
                        sock.send(self._partial)
                    except OSError:
                        pass
            if tick % 50 == 0:  # keep the slow readers talking so silence is not why they go
                timing = encode_packet([MoosMessage(TIMING, DOUBLE, key=b"_async_timing", msg_time=1.0)])
                for sock in self.socks:
                    try:
                        sock.send(timing)
                    except OSError:
                        pass

    def __enter__(self) -> Attack:
        self.thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop.set()
        self.thread.join(10)
        for sock in self.socks:
            sock.close()


def test_good_clients_unaffected_by_slow_readers_and_partial_packets(tmp_path: Path) -> None:
    caps = [f"--max_outbox_bytes={OUTBOX_CAP}", f"--max_buffered_bytes={TOTAL_CAP}",
            f"--max_packet_bytes={PACKET_CAP}"]
    with moosdb_process(tmp_path, extra_args=caps) as db:
        pid = db.pid
        with connected_comms(db.port, "alice", ["SEQ_B"]) as alice, connected_comms(db.port, "bob", ["SEQ_A"]) as bob:
            rss_start = rss(pid)
            arrivals: dict[str, list[tuple[float, int]]] = {"SEQ_A": [], "SEQ_B": []}
            sent_at = [0.0] * PER_CLIENT
            peak = [rss_start]
            late = [0.0]  # how late a 0.1 s sleep wakes up here: the machine's own stalls, not the DB's
            done = threading.Event()

            def receive(client, key: str) -> None:
                got = arrivals[key]
                while len(got) < PER_CLIENT and not done.is_set():
                    now = time.monotonic()
                    got.extend((now, int(m.double())) for m in client.fetch() if m.key() == key)
                    time.sleep(0.002)

            def sample() -> None:
                while True:
                    before = time.monotonic()
                    if done.wait(0.1):
                        return
                    late[0] = max(late[0], time.monotonic() - before - 0.1)
                    peak[0] = max(peak[0], rss(pid))

            threads = [threading.Thread(target=receive, args=(bob, "SEQ_A")),
                       threading.Thread(target=receive, args=(alice, "SEQ_B")),
                       threading.Thread(target=sample)]
            with Attack(db.port) as attack:
                time.sleep(1.0)  # let the attack build up before the good traffic starts
                for t in threads:
                    t.start()
                for i in range(PER_CLIENT):  # 1,000 a second each, in bursts of 10 every 10 ms
                    sent_at[i] = time.monotonic()
                    assert alice.notify("SEQ_A", float(i))
                    assert bob.notify("SEQ_B", float(i))
                    if i % 10 == 9:
                        time.sleep(0.01)
                wait_until(lambda: all(len(v) >= PER_CLIENT for v in arrivals.values()), 30, "every arrival")
            done.set()
            for t in threads:
                t.join(10)
            time.sleep(1.0)  # the attackers' connections are closed: their buffers must be given back
            rss_end = rss(pid)
            with Attack(db.port) as again:  # a second attack, good traffic idle: nothing may accumulate
                wait_until(lambda: again.slow >= 5 and again.partial >= 3, 30, "the second attack")
            time.sleep(1.0)
            rss_again = rss(pid)

        log = db.log_path.read_text()
        worst = {}
        for key, got in arrivals.items():
            assert [n for _, n in got] == list(range(PER_CLIENT)), f"{key}: lost or reordered"
            # A gap the DB caused is a growth of latency between consecutive messages; one the sender caused
            # (this process starved of CPU on a loaded machine) is not, so it is measured against send times.
            latency = [t - sent_at[n] for t, n in got]
            gaps = [b - a for a, b in zip(latency, latency[1:], strict=False)]
            worst[key] = max(gaps)
            # On a loaded shared machine every process stalls now and then; such stalls (seen by a sleeper
            # here) are added to the 200 ms bound, so only the DB's own hold-ups count (the were 6 s).
            assert max(gaps) < 0.2 + late[0], \
                f"{key}: the DB held good messages back {max(gaps) * 1000:.0f} ms (machine stalls {late[0] * 1000:.0f} ms)"
        assert attack.slow >= 10 and attack.partial >= 5
        assert "not keeping up: outbox full" in log and "slow" in log
        assert "max_buffered_bytes" in log and "partial" in log
        assert "pausing" not in log
        print(f"max gaps {[round(max(b[0] - a[0] for a, b in zip(g, g[1:], strict=False)) * 1000) for g in arrivals.values()]} ms "
              f"(caused by the DB {[round(w * 1000) for w in worst.values()]} ms, machine stalls {late[0] * 1000:.0f} ms), "
              f"RSS {rss_start >> 20} -> peak {peak[0] >> 20} -> end {rss_end >> 20} -> after a second attack "
              f"{rss_again >> 20} MiB, slow {attack.slow}, partial {attack.partial}")
        assert peak[0] - rss_start < TOTAL_CAP + RSS_SLACK, (rss_start, peak[0])
        # Given back: what stays is the interpreter's own heap, not the attackers' buffers (up to the cap) ...
        assert rss_end - rss_start < TOTAL_CAP + HEAP_SLACK, (rss_start, rss_end)
        # ... and a second attack leaves nothing more behind (a leak would add its buffers again).
        assert rss_again - rss_end < LEAK_SLACK, (rss_end, rss_again)
