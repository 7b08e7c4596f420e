"""Subscriber tracking across reconnections (``subscriber_watch.py``), driven with hand-set times."""

from __future__ import annotations

import pytest

from gateway.moos.codec import decode_packet, encode_message, frame_packet
from gateway.moos.message import DOUBLE, NOTIFY, REGISTER, MoosMessage
from gateway.moos.subscriber_watch import (
    RESUBSCRIBE_POLL_S,
    RESUBSCRIBE_WAIT_S,
    SUMMARY_PERIOD_S,
    SubscriberWatch,
    is_summary_reply,
    parse_proc_summary,
    summary_request,
)


def post(key: bytes, value: float, kind: bytes = NOTIFY) -> bytes:
    return encode_message(MoosMessage(kind, DOUBLE, 1, src=b"me", key=key, dval=value))


def keys(wire: list[bytes]) -> list[tuple[bytes, float]]:
    return [(m.raw_key, m.dval) for m in decode_packet(frame_packet(wire))] if wire else []


def watching(subscribers: dict[bytes, frozenset[bytes]]) -> SubscriberWatch:
    watch = SubscriberWatch()
    watch.summary(subscribers)
    watch.lost()
    return watch


def test_parse_proc_summary_keeps_others_subscriptions_to_what_we_publish() -> None:
    lines = [b"me:SUBSCRIBED=,X,PUBLISHED=,X", b"a:SUBSCRIBED=,X,Y,PUBLISHED=", b"b:SUBSCRIBED=,X,PUBLISHED=,Y",
             b"c:SUBSCRIBED=,PUBLISHED=,X"]
    assert parse_proc_summary(lines, b"me", [b"X"]) == {b"X": frozenset({b"a", b"b"})}


def test_our_request_and_its_replies_are_told_apart() -> None:
    (request,) = decode_packet(frame_packet([summary_request(b"me", 3.0)]))
    assert request.raw_src == b"me" and is_summary_reply(request)
    other = request.copy()
    other.msg_id = -2  # an application's server_request()
    assert not is_summary_reply(other)


def test_mail_of_a_variable_with_subscribers_waits_until_they_are_back() -> None:
    watch = watching({b"X": frozenset({b"a", b"b"}), b"LONELY": frozenset()})
    assert watch.missing == {b"X"}
    outbox = [post(b"X", 1), post(b"Y", 2), post(b"X", 3, REGISTER), post(b"X", 4)]
    assert keys(watch.reconnected(10.0, outbox)) == [(b"Y", 2), (b"X", 3)]  # a registration is not mail
    assert watch.summary({b"X": frozenset({b"a"})}) is None  # b is not back yet
    assert watch.missing == {b"X"}
    assert keys(watch.summary({b"X": frozenset({b"a", b"b", b"c"})}) or []) == [(b"X", 1), (b"X", 4)]
    assert not watch.missing and not watch.held


def test_waiting_gives_up_after_resubscribe_wait() -> None:
    watch = watching({b"X": frozenset({b"a"})})
    watch.reconnected(10.0, [post(b"X", 1)])
    early = watch.poll(10.0 + RESUBSCRIBE_WAIT_S - 0.01, publishing=True)
    assert early.ask and not early.gave_up and not early.release
    late = watch.poll(10.0 + RESUBSCRIBE_WAIT_S, publishing=True)
    assert late.gave_up == {b"X"} and keys(late.release) == [(b"X", 1)] and not watch.missing


def test_no_giving_up_before_the_reconnection() -> None:
    watch = watching({b"X": frozenset({b"a"})})
    assert not watch.poll(1e9, publishing=True).gave_up  # still down: the wait starts at reconnection


def test_requests_are_quick_while_waiting_and_slow_otherwise() -> None:
    watch = SubscriberWatch()
    assert not watch.poll(100.0, publishing=False).ask  # publishes nothing: asks nothing
    assert watch.poll(100.0, publishing=True).ask and watch.pending
    assert not watch.poll(100.0 + SUMMARY_PERIOD_S / 2, publishing=True).ask
    assert watch.next_poll_in(100.5) == float("inf")
    watch.summary({b"X": frozenset({b"a"})})
    watch.lost()
    watch.reconnected(200.0, [])
    assert watch.poll(200.0, publishing=True).ask
    assert watch.next_poll_in(200.0) == pytest.approx(RESUBSCRIBE_POLL_S)
    assert not watch.poll(200.0 + RESUBSCRIBE_POLL_S / 2, publishing=True).ask
    assert watch.poll(200.0 + RESUBSCRIBE_POLL_S, publishing=True).ask


def test_lost_again_while_waiting_still_waits_for_the_first_subscribers() -> None:
    watch = watching({b"X": frozenset({b"a"})})
    watch.reconnected(10.0, [])
    watch.summary({b"X": frozenset({b"b"})})  # b came, a did not
    watch.lost()
    assert watch.expected == {b"X": frozenset({b"a", b"b"})} and watch.missing == {b"X"}
    watch.reconnected(20.0, [])
    assert watch.summary({b"X": frozenset({b"b"})}) is None
    assert watch.summary({b"X": frozenset({b"a", b"b"})}) == []
