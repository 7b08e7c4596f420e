"""The DB's hot path over a packet's bytes (``db_wire.py``) does exactly what ``MoosDatabase.process`` does with
the decoded messages: same variables, counts, refusals, held mail (byte for byte once decoded) and summaries."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gateway.moos.clock import MoosClock
from gateway.moos.codec import PACKET_HEADER_SIZE, decode_packet, encode_packet, frame_packet
from gateway.moos.database import MoosDatabase
from gateway.moos.db_wire import process_wire
from gateway.moos.errors import ProtocolError
from gateway.moos.message import BINARY, DOUBLE, NOTIFY, REGISTER, STRING, UNREGISTER, MoosMessage


class FixedClock(MoosClock):
    def local_time(self, apply_warp: bool = True) -> float:
        return 5000.0


def make_db(max_stored_bytes: int, max_name_bytes: int) -> MoosDatabase:
    db = MoosDatabase("moos", FixedClock(), max_stored_bytes=max_stored_bytes, max_name_bytes=max_name_bytes)
    for name in (b"a", b"s", b"t"):
        db.connect(name, True)
    db.process([MoosMessage(REGISTER, DOUBLE, 1, src=b"s", key=b"K0", dval=0.0),
                MoosMessage(REGISTER, DOUBLE, 2, src=b"s", key=b"K1", dval=0.0),
                MoosMessage(REGISTER, DOUBLE, 3, src=b"t", key=b"K1", dval=1.0)], b"s")
    return db


messages = st.lists(st.one_of(
    st.builds(lambda key, src, com, aux, kind, value, t: MoosMessage(
        NOTIFY, kind, 7, src=src, aux=aux, community=com, key=key, msg_time=t,
        dval=value if kind == DOUBLE else -1.0, sval=b"" if kind == DOUBLE else b"v%d" % int(value)),
        st.sampled_from([b"K0", b"K1", b"K2"]), st.sampled_from([b"a", b"a", b"b", b"L" * 20]),
        st.sampled_from([b"", b"", b"moos", b"far"]), st.sampled_from([b"", b"", b"x"]),
        st.sampled_from([DOUBLE, DOUBLE, DOUBLE, STRING, BINARY]), st.integers(0, 300).map(float),
        st.sampled_from([1.0, 2.0])),
    st.builds(lambda kind, key: MoosMessage(kind, DOUBLE, 8, src=b"t", key=key, dval=0.0),
              st.sampled_from([REGISTER, UNREGISTER]), st.sampled_from([b"K0", b"K2"])),
), min_size=1, max_size=40)


def state(db: MoosDatabase) -> object:
    variables = {name: (v.data_type, v.dval, v.sval, v.writer, v.aux, v.community, v.written, v.msg_time,
                        sorted(v.writers), v.seq, sorted(v.subscribers)) for name, v in db.vars.items()}
    mail = {}
    for name in (b"a", b"s", b"t"):
        chunks, count = db.take_mail(name)
        mail[name] = [(m.msg_type, m.data_type, m.raw_src, m.raw_aux, m.raw_community, m.raw_key, m.msg_time, m.dval,
                       m.raw_sval) for m in decode_packet(frame_packet(chunks, count))] if count else []
    return variables, mail, dict(db.refusals), db.limits.stored_bytes, db.rejected_writes, db.rw_summary()


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(batches=st.lists(messages, min_size=1, max_size=4), stored=st.sampled_from([10**9, 2200]),
       names=st.sampled_from([256, 10]))
def test_wire_path_equals_the_message_path(batches: list[list[MoosMessage]], stored: int, names: int) -> None:
    by_message, by_wire = make_db(stored, names), make_db(stored, names)
    for batch in batches:
        packet = encode_packet(batch)
        replies_m, notified_m = by_message.process(decode_packet(packet), b"a")
        replies_w, notified_w = process_wire(by_wire, packet, PACKET_HEADER_SIZE, len(packet), len(batch), b"a")
        assert (replies_m, notified_m) == (replies_w, notified_w)
    assert state(by_message) == state(by_wire)


def test_a_run_is_forwarded_as_received_when_it_carries_the_community() -> None:
    db = make_db(10**9, 256)
    run = [MoosMessage(NOTIFY, DOUBLE, i, src=b"a", community=b"moos", key=b"K0", msg_time=1.0, dval=float(i))
           for i in range(100)]
    db.process(run[:1], b"a")  # the first write of K0 goes the long way (type, filters)
    db.take_mail(b"s")
    packet = encode_packet(run[1:])
    process_wire(db, packet, PACKET_HEADER_SIZE, len(packet), 99, b"a")
    chunks, count = db.take_mail(b"s")
    assert count == 99 and chunks == [packet[PACKET_HEADER_SIZE:]]  # one slice, the bytes that came in
    assert db.vars[b"K0"].dval == 99.0 and db.vars[b"K0"].written == 100


def test_a_count_that_disagrees_with_the_body_is_a_protocol_error() -> None:
    db = make_db(10**9, 256)
    packet = encode_packet([MoosMessage(NOTIFY, DOUBLE, 1, src=b"a", key=b"K0", dval=1.0)] * 3)
    with pytest.raises(ProtocolError, match="says 4 messages"):
        process_wire(db, packet, PACKET_HEADER_SIZE, len(packet), 4, b"a")
    with pytest.raises(ProtocolError):
        process_wire(db, packet, PACKET_HEADER_SIZE, len(packet) - 3, 3, b"a")
