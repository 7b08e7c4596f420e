"""Issue 23, the moos-db side: one client never takes the DB down for the others, and nothing is refused silently.

Each test is an attack that worked before: a huge request stalling the DB (and the stall blamed on a good client),
unbounded variables and names, a type lock that shut a writer out without a word, a name squatter after a
restart, and a binary mission file served on defaults.
"""

from __future__ import annotations

import contextlib
import gc
import logging
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from gateway.moos.clock import MoosClock
from gateway.moos.codec import PROTOCOL_BYTES, PacketReader, encode_packet
from gateway.moos.database import MoosDatabase
from gateway.moos.message import (
    DATA,
    DOUBLE,
    NOTIFY,
    POISON,
    REGISTER,
    SERVER_REQUEST,
    STRING,
    WELCOME,
    MoosMessage,
)
from gateway.moos.server import MoosDB
from gateway.moos.testing import collect_mail, connected_comms, moosdb_process, running_moosdb
from util.process import wait_until

BIN = Path(sys.executable).parent


# ---- raw clients -----------------------------------------------------------------------------------------------
@contextlib.contextmanager
def raw_client(port: int, name: bytes) -> Iterator[tuple[socket.socket, list[MoosMessage]]]:
    """A hand-made async client: handshake as ``name``; yields the socket and the DB's first packet."""
    sock = socket.create_connection(("127.0.0.1", port), timeout=10)
    try:
        hello = MoosMessage(DATA, STRING, key=b"asynchronous", msg_time=time.time(), sval=name)
        sock.sendall(PROTOCOL_BYTES + encode_packet([hello]))
        yield sock, read_packet(sock)
    finally:
        sock.close()


def read_packet(sock: socket.socket, timeout: float = 10.0) -> list[MoosMessage]:
    reader = PacketReader()
    sock.settimeout(timeout)
    while True:
        data = sock.recv(65536)
        if not data:
            return []
        packets = reader.feed(data)
        if packets:
            return packets[0]


def notifies(name: bytes, keys: range, prefix: bytes = b"V") -> bytes:
    return encode_packet([MoosMessage(NOTIFY, DOUBLE, i, src=name, key=prefix + b"%07d" % i, dval=float(i))
                          for i in keys])


# ---- 1. long requests, and silence blamed on the right client ---------------------------------------------------
def test_requests_over_many_variables_never_hold_the_db_for_long() -> None:
    """PROC_SUMMARY, ALL, VAR_SUMMARY and the DB_* summaries over 60,000 variables: no call holds it > 50 ms CPU."""
    db = MoosDatabase("c", MoosClock(), max_variables=10**6, max_variables_per_client=10**6)
    for name in (b"hog", b"a", b"b"):
        db.connect(name, True)
    for start in range(0, 60_000, 1000):
        db.process([MoosMessage(NOTIFY, DOUBLE, 1, src=b"hog", key=b"V%07d" % i, dval=1.0)
                    for i in range(start, start + 1000)], b"hog")
    db.process([MoosMessage(REGISTER, DOUBLE, 1, src=b"a", key=b"V0000007", dval=0.0)], b"a")
    for name in (b"hog", b"a", b"b"):
        db.take_mail(name)
    worst = 0.0
    gc.collect()
    gc.disable()  # a full collection's pause is CPython's (all live objects), not this request's
    try:
        db._summary_time -= 10  # the next packet also starts DB_VARSUMMARY and DB_RWSUMMARY
        for what in (b"PROC_SUMMARY", b"ALL", b"VAR_SUMMARY"):
            started = time.thread_time()
            replies, _ = db.process([MoosMessage(SERVER_REQUEST, STRING, -2, src=b"b", key=what)], b"b")
            worst = max(worst, time.thread_time() - started)
            assert replies == []  # too big for one slice: held for b when done
        while db.jobs_pending:
            started = time.thread_time()
            db.run_jobs()
            worst = max(worst, time.thread_time() - started)
    finally:
        gc.enable()
    assert worst < 0.05, f"one call held the DB for {worst * 1000:.0f} ms of CPU"
    from gateway.moos.codec import decode_packet, frame_packet
    got = decode_packet(frame_packet(*db.take_mail(b"b")))
    procs = [m.string() for m in got if m.key() == "PROC_SUMMARY"]
    assert "a:SUBSCRIBED=,V0000007,PUBLISHED=" in procs and len(procs) == 3
    assert sum(1 for m in got if m.key().startswith("V0")) == 60_000  # ALL, in one packet
    (names,) = [m.string() for m in got if m.key() == "VAR_SUMMARY"]
    assert names.split(",")[:2] == ["DB_CLIENTS", "DB_EVENT"] and len(names.split(",")) == 60_008
    assert db.vars[b"DB_VARSUMMARY"].sval.startswith(b"DB_CLIENTS")
    assert b"hog=&" in db.vars[b"DB_RWSUMMARY"].sval


def test_a_huge_request_does_not_stall_or_drop_good_clients(tmp_path: Path) -> None:
    """A client creates 100,000 variables and asks PROC_SUMMARY and ALL; a good pair keeps talking meanwhile."""
    with moosdb_process(tmp_path, extra_args=["--max_variables=200000", "--max_variables_per_client=200000"]) as db, \
            connected_comms(db.port, "alice", ["PING"]) as alice, connected_comms(db.port, "bob", ["PONG"]) as bob:
        with raw_client(db.port, b"hog") as (sock, welcome):
            assert welcome[0].msg_type == WELCOME
            for start in range(0, 100_000, 2000):
                sock.sendall(notifies(b"hog", range(start, start + 2000)))
            wait_until(lambda: len(alice.server_request("VAR_SUMMARY", 10)[0].string().split(",")) > 100_000, 60,
                       "100,000 variables")
            sock.sendall(encode_packet([MoosMessage(SERVER_REQUEST, STRING, -2, src=b"hog", key=b"PROC_SUMMARY"),
                                        MoosMessage(SERVER_REQUEST, STRING, -2, src=b"hog", key=b"ALL")]))
            worst = 0.0
            for i in range(40):
                sent = time.monotonic()
                alice.notify("PONG", float(i))
                got = collect_mail(bob, ["PONG"], until=1, timeout=20)
                assert [m.double() for m in got] == [float(i)]
                worst = max(worst, time.monotonic() - sent)
                time.sleep(0.05)
        assert worst < 1.0, f"a round trip took {worst:.1f} s"
        assert alice.is_connected() and bob.is_connected()
    log = db.log_path.read_text()
    assert "dropping client 'alice'" not in log and "dropping client 'bob'" not in log


def test_a_busy_db_does_not_blame_its_stall_on_a_quiet_client() -> None:
    """The loop is held 4 s by one packet; a client whose heartbeat waited in the kernel is not dropped."""
    with running_moosdb(client_timeout=2.0) as db:
        real_notify = db.db.notify

        def stalling(msg: MoosMessage, now: float | None = None, client: bytes | None = None) -> bool:
            if msg.raw_key == b"STALL":
                time.sleep(4.0)
            return real_notify(msg, now, client)

        db.db.notify = stalling  # type: ignore[method-assign]
        with connected_comms(db.port, "alice", ["AFTER"]) as alice, connected_comms(db.port, "staller") as staller:
            staller.notify("STALL", 1.0)
            time.sleep(5.0)
            alice.notify("AFTER", 2.0)
            assert [m.double() for m in collect_mail(alice, ["AFTER"], until=1)] == [2.0]
            assert db.client_names() == ["alice", "staller"]
        assert not [who for who, _ in db.dropped if "alice" in who]


# ---- 2. caps on variables, names and stored bytes ---------------------------------------------------------------
def test_variable_caps_refuse_and_name_the_client(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, "gateway.moos")
    with running_moosdb(max_variables=60, max_variables_per_client=20) as db, \
            connected_comms(db.port, "alice", ["OK", "DB_REFUSED"]) as alice:
        with raw_client(db.port, b"hog") as (sock, _):
            sock.sendall(notifies(b"hog", range(30)))  # 20 created, 10 refused
            wait_until(lambda: db.db.refusals.get((b"hog", "max_variables_per_client")) == 10, 10, "refusals")
        for n in range(3):
            with raw_client(db.port, b"hog%d" % n) as (sock, _):
                sock.sendall(notifies(b"hog%d" % n, range(20), b"H%d_" % n))
                wait_until(lambda n=n: (b"H%d_%07d" % (n, 19)) in db.db.vars or len(db.db.vars) >= 60, 10, "writes")
        # the DB may be full before hog2's packet is read: wait for its refusal, not for a variable
        wait_until(lambda: db.db.refusals.get((b"hog2", "max_variables"), 0) > 0, 10, "hog2's refusals")
        assert len(db.db.vars) == 60
        alice.notify("OK", 1.0)  # existing variables still work
        got = collect_mail(alice, ["OK", "DB_REFUSED"], until=lambda m: any(
            x.key() == "DB_REFUSED" and "hog:max_variables_per_client=10" in x.string() for x in m), timeout=10)
        assert [m.double() for m in got if m.key() == "OK"] == [1.0]
    lines = [r.getMessage() for r in caplog.records if "max_variables_per_client" in r.getMessage()]
    assert len(lines) == 1 and "'hog'" in lines[0] and "(20)" in lines[0]  # named once, not 10 times


def test_huge_names_are_refused_and_never_echoed(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, "gateway.moos")
    with running_moosdb(max_stored_bytes=10_000_000) as db, connected_comms(db.port, "alice", ["OK"]) as alice:
        with raw_client(db.port, b"N" * 50_000_000) as (_, reply):
            assert reply[0].msg_type == POISON and "max_name_bytes (256)" in reply[0].string()
        with raw_client(db.port, b"writer") as (sock, _):
            sock.sendall(encode_packet([
                MoosMessage(NOTIFY, DOUBLE, 1, src=b"writer", key=b"K" * 300, dval=1.0),
                MoosMessage(NOTIFY, DOUBLE, 2, src=b"S" * 300, key=b"OK", dval=2.0),
                MoosMessage(NOTIFY, DOUBLE, 3, src=b"writer", aux=b"A" * 300, key=b"OK", dval=3.0),
                MoosMessage(NOTIFY, STRING, 4, src=b"writer", key=b"BIG", sval=b"x" * 11_000_000),
                MoosMessage(NOTIFY, DOUBLE, 5, src=b"writer", key=b"OK", dval=5.0),
            ]))
            got = collect_mail(alice, ["OK"], until=1)
        assert [m.double() for m in got] == [5.0]
        assert b"K" * 300 not in db.db.vars and b"BIG" not in db.db.vars
        refused = {cause for (who, cause) in db.db.refusals if who == b"writer"}
        assert refused == {"max_name_bytes", "max_stored_bytes"}
        wait_until(lambda: db.client_names() == ["alice"], 10, "writer's leave")
    text = "\n".join(r.getMessage() for r in caplog.records)
    assert "N" * 100 not in text and "K" * 100 not in text and len(text) < 20_000


# ---- 3. the type lock is not silent -----------------------------------------------------------------------------
def test_a_type_locked_write_is_logged_naming_both_clients_and_counted(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, "gateway.moos")
    with running_moosdb() as db, connected_comms(db.port, "squatter") as squatter, \
            connected_comms(db.port, "owner", ["DB_REFUSED"]) as owner:
        squatter.notify("DEPLOY", 0.0)  # typed double first
        wait_until(lambda: b"DEPLOY" in db.db.vars and db.db.vars[b"DEPLOY"].written, 10, "DEPLOY")
        for _ in range(5):
            assert owner.notify("DEPLOY", "true")  # MOOS on the wire: accepted by the client, refused by the DB
        got = collect_mail(owner, ["DB_REFUSED"], until=lambda m: any(
            "owner:type_mismatch=5" in x.string() for x in m), timeout=10)
        assert got
    (line,) = [r.getMessage() for r in caplog.records if "DEPLOY" in r.getMessage()]
    assert "'owner'" in line and "'squatter'" in line and "type D" in line and "type S" in line


# ---- 4. a name squatter -----------------------------------------------------------------------------------------
def test_a_duplicate_name_is_refused_naming_the_holder(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, "gateway.moos")
    with running_moosdb() as db, connected_comms(db.port, "pHelmIvP"):
        with raw_client(db.port, b"pHelmIvP") as (sock, reply):
            assert reply[0].msg_type == POISON
            mine = "{}:{}".format(*sock.getsockname())
        holder = next(r.getMessage() for r in caplog.records if "second client named" in r.getMessage())
        assert mine in holder and "connected from 127.0.0.1:" in holder
        assert "connected from 127.0.0.1:" in reply[0].string()
        assert db.client_names() == ["pHelmIvP"]


def test_a_silent_holder_of_a_name_is_replaced_by_the_new_connection() -> None:
    """A squatter (or a dead peer's half-open socket) that holds a name but says nothing does not lock it."""
    with running_moosdb(client_timeout=4.0) as db:
        with raw_client(db.port, b"pHelmIvP") as (_, reply):
            assert reply[0].msg_type == WELCOME
            time.sleep(2.5)  # silent for more than half the client timeout, not yet timed out
            with connected_comms(db.port, "pHelmIvP", ["X"]) as real:
                assert real.get_fatal_error() is None
                real.notify("X", 1.0)
                assert [m.double() for m in collect_mail(real, ["X"], until=1)] == [1.0]
        assert any("replaced by a new connection" in reason for _, reason in db.dropped)


# ---- 5. a binary mission file -----------------------------------------------------------------------------------
@pytest.mark.parametrize("data, what", [
    (b"ServerPort = 9000\n\x00\x01\x02" + bytes(range(256)) * 8, "NUL byte"),
    (bytes(range(128, 256)) * 20, "not UTF-8"),
])
def test_moos_db_refuses_a_binary_mission_file(tmp_path: Path, data: bytes, what: str) -> None:
    mission = tmp_path / "m.moos"
    mission.write_bytes(data)
    run = subprocess.run([str(BIN / "moos-db"), str(mission), "--moos_port=0"], capture_output=True, text=True,
                         timeout=30, cwd=tmp_path)
    assert run.returncode == 2
    assert "m.moos:" in run.stderr and what in run.stderr and "Traceback" not in run.stderr
    assert "listening" not in run.stdout


def test_a_latin1_comment_is_still_a_mission_file(tmp_path: Path) -> None:
    mission = tmp_path / "m.moos"
    mission.write_bytes(b"// caf\xe9 at 20\xb0C\nCommunity = latin\n")
    from gateway.moos.mission_file import MissionFile
    assert MissionFile(mission).community == "latin"


def test_mission_file_limits_and_flags(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``MaxVariables`` and friends come from the mission file; a flag wins."""
    from gateway.apps import moos_db
    mission = tmp_path / "m.moos"
    mission.write_text("ServerPort = 0\nMaxVariables = 30\nMaxVariablesPerClient = 9\n")
    got: dict[str, int] = {}

    class Capture(MoosDB):
        def start(self) -> MoosDB:
            got.update(max_variables=self.db.max_variables, per_client=self.db.max_variables_per_client)
            raise OSError("not started in this test")

    monkeypatch.setattr(moos_db, "MoosDB", Capture)
    assert moos_db.main([str(mission), "--max_variables_per_client=7"]) == 1
    assert got == {"max_variables": 30, "per_client": 7}
