"""The MOOSDB's caps (``db_limits.py``) on their own: what is refused, what is charged, what DB_REFUSED says."""

from __future__ import annotations

from gateway.moos.database import DBVar
from gateway.moos.db_limits import MAX_REFUSAL_KEYS, DBLimits, cut, preview
from gateway.moos.message import DOUBLE, NOTIFY, STRING, MoosMessage


def write(key: bytes, sval: bytes = b"", src: bytes = b"w", aux: bytes = b"") -> MoosMessage:
    return MoosMessage(NOTIFY, STRING, 1, src=src, aux=aux, key=key, sval=sval)


def test_creation_caps_per_client_and_per_db() -> None:
    limits = DBLimits(max_variables=5, max_variables_per_client=2, max_name_bytes=8)
    assert limits.may_create(b"a", b"V1", "write", 0) and limits.may_create(b"a", b"V2", "write", 1)
    assert not limits.may_create(b"a", b"V3", "write", 2)  # its third
    assert limits.may_create(b"b", b"V3", "write", 2)  # another client still may
    assert not limits.may_create(b"c", b"V4", "write", 5)  # the DB is full
    assert not limits.may_create(b"c", b"NINE_LONG", "registration", 0)
    assert limits.created_by == {b"a": 2, b"b": 1}
    assert limits.refusals == {(b"a", "max_variables_per_client"): 1, (b"c", "max_variables"): 1,
                               (b"c", "max_name_bytes"): 1}


def test_stored_bytes_cap_refuses_growth_only() -> None:
    limits = DBLimits(max_stored_bytes=100)
    limits.stored_bytes = 95
    assert not limits.may_store(write(b"K", b"x" * 10), None, b"w")
    var = DBVar(b"K", STRING)
    var.sval, var.writer = b"x" * 50, b"w"
    assert limits.may_store(write(b"K", b"x" * 10), var, b"w")  # smaller than what it replaces
    assert limits.refusals == {(b"w", "max_stored_bytes"): 1}
    number = MoosMessage(NOTIFY, DOUBLE, 1, src=b"w", key=b"K", dval=1e300)
    assert limits.may_store(number, var, b"w")  # a double's value is not stored as bytes


def test_long_source_aux_or_community_is_refused() -> None:
    limits = DBLimits(max_name_bytes=4)
    assert limits.names_fit(write(b"K", src=b"abcd"), b"abcd")
    assert not limits.names_fit(write(b"K", aux=b"abcde"), b"abcd")
    assert limits.refusals == {(b"abcd", "max_name_bytes"): 1}


def test_db_refused_is_reported_only_when_it_changed() -> None:
    limits = DBLimits()
    assert limits.refused_report() is None
    limits.refuse(b"hog", "max_variables", "refused %s", "x")
    limits.refuse(b"hog", "max_variables", "refused %s", "x")
    assert limits.refused_report() == b"hog:max_variables=2"
    assert limits.refused_report() is None
    limits.refuse(b"pig", "type_mismatch", "refused")
    assert limits.refused_report() == b"hog:max_variables=2,pig:type_mismatch=1"


def test_refusal_counters_are_bounded() -> None:
    limits = DBLimits()
    for i in range(MAX_REFUSAL_KEYS + 5):
        limits.refuse(b"c%d" % i, "max_variables", "refused")
    assert len(limits.refusals) == MAX_REFUSAL_KEYS + 1 and limits.refusals[(b"*", "max_variables")] == 5


def test_preview_and_cut_bound_what_a_client_sent() -> None:
    assert preview(b"short") == "'short'"
    assert preview(b"x" * 100, 10) == "'xxxxxxxxxx'... (100 bytes)"
    assert cut(b"abcdef", 3) == b"abc...(cut)" and cut(b"abc", 3) == b"abc"
