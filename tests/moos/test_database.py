"""MOOSDB semantics without sockets (spec §8), driven with a hand-set clock."""

from __future__ import annotations

import pytest

from gateway.moos.clock import MoosClock
from gateway.moos.codec import decode_packet, frame_packet
from gateway.moos.database import MoosDatabase, parse_filter
from gateway.moos.message import (
    BINARY,
    DOUBLE,
    NOTIFY,
    REGISTER,
    SERVER_REQUEST,
    STRING,
    UNREGISTER,
    WILDCARD_REGISTER,
    WILDCARD_UNREGISTER,
    MoosMessage,
)
from gateway.moos.wildcard import wild_match


class ManualClock(MoosClock):
    """Test double: a MOOS clock whose time only moves when the test says so."""

    def __init__(self, start: float = 1000.0) -> None:
        super().__init__(1.0)
        self.now = start

    def local_time(self, apply_warp: bool = True) -> float:
        return self.now


@pytest.fixture
def clock() -> ManualClock:
    return ManualClock()


@pytest.fixture
def db(clock: ManualClock) -> MoosDatabase:
    database = MoosDatabase("c1", clock)
    for name in (b"pub", b"sub", b"other"):
        database.connect(name, True)
    for name in (b"pub", b"sub", b"other"):
        database.take_mail(name)
    return database


def mail(db: MoosDatabase, who: bytes = b"sub") -> list[MoosMessage]:
    chunks, count = db.take_mail(who)
    return decode_packet(frame_packet(chunks, count)) if count else []


def notify(db: MoosDatabase, key: str, value: float | str | bytes, src: bytes = b"pub", t: float = 5.0) -> None:
    if isinstance(value, float):
        msg = MoosMessage(NOTIFY, DOUBLE, 7, src=src, key=key.encode(), msg_time=t, dval=value)
    elif isinstance(value, bytes):
        msg = MoosMessage(NOTIFY, BINARY, 7, src=src, key=key.encode(), msg_time=t, sval=value)
    else:
        msg = MoosMessage(NOTIFY, STRING, 7, src=src, key=key.encode(), msg_time=t, sval=value.encode())
    db.process([msg])


def register(db: MoosDatabase, key: str, period: float = 0.0, src: bytes = b"sub") -> None:
    db.process([MoosMessage(REGISTER, DOUBLE, 1, src=src, key=key.encode(), dval=period)])


def wildcard(db: MoosDatabase, var: str, app: str, period: float = 0.0, kind: bytes = WILDCARD_REGISTER) -> None:
    sval = f"AppPattern={app},VarPattern={var},Interval={period:g}".encode()
    db.process([MoosMessage(kind, STRING, 1, src=b"sub", key=b"sub", sval=sval)])


def test_forwarded_notification_keeps_id_src_time_and_gets_the_community(db: MoosDatabase) -> None:
    register(db, "X")
    notify(db, "X", 2.5, t=123.0)
    (msg,) = mail(db)
    assert (msg.type(), msg.msg_id, msg.source(), msg.time(), msg.double(), msg.community()) == \
        ("N", 7, "pub", 123.0, 2.5, "c1")


def test_foreign_community_is_preserved(db: MoosDatabase) -> None:
    register(db, "X")
    db.process([MoosMessage(NOTIFY, DOUBLE, 1, src=b"bridge", community=b"far", key=b"X", dval=1.0)])
    assert mail(db)[0].community() == "far"


def test_register_sends_current_value_with_id_minus_one(db: MoosDatabase) -> None:
    notify(db, "S", "text", t=42.0)
    register(db, "S")
    (msg,) = mail(db)
    assert (msg.msg_id, msg.string(), msg.double(), msg.time(), msg.source()) == (-1, "text", -1.0, 42.0, "pub")


def test_register_for_unwritten_variable_sends_nothing(db: MoosDatabase) -> None:
    register(db, "NOBODY")
    assert mail(db) == []
    assert db.vars[b"NOBODY"].data_type == b"~"


def test_type_lock_rejects_and_counts(db: MoosDatabase) -> None:
    register(db, "T")
    notify(db, "T", 1.0)
    notify(db, "T", "no")
    notify(db, "T", b"bin")
    assert [m.double() for m in mail(db)] == [1.0]
    assert db.rejected_writes == 2


def test_variable_created_by_register_takes_the_first_writers_type(db: MoosDatabase) -> None:
    register(db, "LATE")
    notify(db, "LATE", "first")
    notify(db, "LATE", 1.0)
    assert [m.string() for m in mail(db)] == ["first"]


def test_interval_drops_notifications_inside_the_period(db: MoosDatabase, clock: ManualClock) -> None:
    register(db, "F", 1.0)
    for i in range(6):
        notify(db, "F", float(i))
        clock.now += 0.25
    assert [m.double() for m in mail(db)] == [0.0, 4.0]


def test_reregistering_changes_the_period(db: MoosDatabase, clock: ManualClock) -> None:
    register(db, "F", 10.0)
    notify(db, "F", 0.0)
    clock.now += 0.1
    register(db, "F", 0.0)  # also resends the current value
    notify(db, "F", 1.0)
    assert [m.double() for m in mail(db)] == [0.0, 0.0, 1.0]


def test_unregister(db: MoosDatabase) -> None:
    register(db, "U")
    db.process([MoosMessage(UNREGISTER, DOUBLE, 1, src=b"sub", key=b"U")])
    notify(db, "U", 1.0)
    assert mail(db) == []


def test_wildcards_match_writer_and_name(db: MoosDatabase) -> None:
    notify(db, "NAV_X", 1.0, src=b"pNav")
    notify(db, "NAV_Y", 2.0, src=b"other")
    wildcard(db, "NAV_*", "pN?v")
    assert [m.key() for m in mail(db)] == ["NAV_X"]
    notify(db, "NAV_Z", 3.0, src=b"pNav")  # first write of a new variable re-checks the filters
    notify(db, "NAV_Q", 3.0, src=b"other")
    assert [m.key() for m in mail(db)] == ["NAV_Z"]


def test_wildcard_filter_survives_unregister_and_first_period_wins(db: MoosDatabase, clock: ManualClock) -> None:
    wildcard(db, "W_*", "*", 5.0)
    wildcard(db, "W_*", "*", 0.0)  # same patterns: the stored period stays 5
    notify(db, "W_A", 1.0)
    clock.now += 1.0
    notify(db, "W_A", 2.0)
    assert [m.double() for m in mail(db)] == [1.0]
    wildcard(db, "W_*", "*", kind=WILDCARD_UNREGISTER)
    clock.now += 10.0
    notify(db, "W_A", 3.0)
    notify(db, "W_NEW", 4.0)
    assert [(m.key(), m.double()) for m in mail(db)] == [("W_NEW", 4.0)]


def test_space_separated_filter_never_matches(db: MoosDatabase) -> None:
    db.process([MoosMessage(WILDCARD_REGISTER, STRING, 1, src=b"sub", key=b"sub",
                            sval=b"AppPattern=* VarPattern=* Interval=0")])
    notify(db, "ANY", 1.0)
    assert mail(db) == []


def test_parse_filter() -> None:
    assert parse_filter(b"AppPattern=p*,VarPattern= X_? ,Interval=0.5") == (b"p*", b"X_?", 0.5)
    assert parse_filter(b"nonsense") == (b"", b"", 0.0)


@pytest.mark.parametrize(
    "pattern, text, expected",
    [(b"*", b"", True), (b"A*", b"ABC", True), (b"A?C", b"ABC", True), (b"A?C", b"AC", False),
     (b"a*", b"ABC", False), (b"[AB]", b"A", False), (b"[AB]", b"[AB]", True), (b"*_X", b"NAV_X", True)],
)
def test_wild_match(pattern: bytes, text: bytes, expected: bool) -> None:
    assert wild_match(pattern, text) is expected


def test_registration_from_unknown_client_is_ignored(db: MoosDatabase) -> None:
    register(db, "GHOSTLY", src=b"ghost")
    notify(db, "GHOSTLY", 1.0)
    assert b"ghost" not in db.held and b"ghost" not in db.vars[b"GHOSTLY"].subscribers


def test_disconnect_cleans_up_and_announces(db: MoosDatabase) -> None:
    register(db, "DB_EVENT", src=b"other")
    assert [m.string() for m in mail(db, b"other")] == ["connected=other"]  # the current value
    register(db, "X")
    wildcard(db, "*", "*")
    db.disconnect(b"sub")
    assert b"sub" not in db.vars[b"X"].subscribers and b"sub" not in db.filters and b"sub" not in db.held
    assert [m.string() for m in mail(db, b"other")] == ["disconnected=sub"]


def test_server_request_all_var_summary_and_proc_summary(db: MoosDatabase, clock: ManualClock) -> None:
    notify(db, "A", 1.0)
    clock.now += 3.0
    notify(db, "B", "bee")
    db.take_mail(b"sub")
    q = MoosMessage(SERVER_REQUEST, STRING, -2, src=b"sub", key=b"ALL")
    replies, _ = db.process([q])
    names = [m.key() for m in replies]
    assert names == sorted(names, reverse=True)
    by = {m.key(): m for m in replies}
    assert all(m.msg_id == -2 for m in replies)
    assert by["A"].double() == 1.0 and by["B"].string() == "bee" and by["B"].source() == "pub"
    assert by["A"].time() == pytest.approx(0.0) and by["B"].time() == pytest.approx(3.0)
    (summary,) = db.process([MoosMessage(SERVER_REQUEST, STRING, -2, key=b"VAR_SUMMARY")])[0]
    assert summary.string().split(",") == sorted(by)
    procs = db.process([MoosMessage(SERVER_REQUEST, STRING, -2, key=b"PROC_SUMMARY")])[0]
    assert "pub:SUBSCRIBED=,PUBLISHED=,A,B" in [m.string() for m in procs]


def test_db_clear_resets_values_and_mail(db: MoosDatabase) -> None:
    register(db, "C")
    notify(db, "C", 1.0)
    db.process([MoosMessage(SERVER_REQUEST, STRING, -2, src=b"sub", key=b"DB_CLEAR")])
    assert db.take_mail(b"sub") == ([], 0)
    notify(db, "C", "now a string")  # the type is learned again
    assert [m.string() for m in mail(db)] == ["now a string"]


def test_db_variables_every_two_seconds(db: MoosDatabase, clock: ManualClock) -> None:
    for var in ("DB_TIME", "DB_UPTIME", "DB_CLIENTS", "DB_VARSUMMARY", "DB_RWSUMMARY"):
        register(db, var)
    assert mail(db) == []  # created but never written
    clock.now += 2.5
    register(db, "X")
    got = {m.key(): m for m in mail(db)}
    assert got["DB_TIME"].double() == clock.now and got["DB_UPTIME"].double() == pytest.approx(2.5)
    assert got["DB_CLIENTS"].string() == "pub,sub,other,"
    assert got["DB_TIME"].source() == "MOOSDB_c1" and got["DB_TIME"].community() == "c1"
    assert "sub=" in got["DB_RWSUMMARY"].string() and "DB_TIME" in got["DB_VARSUMMARY"].string()
    clock.now += 1.0
    register(db, "Y")
    assert mail(db) == []
