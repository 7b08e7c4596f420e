"""DynamicBuffer rules (Goby3 dynamic_buffer.h): merge, push/drop ends, ttl, blackout, ack_timeout, priority."""

from __future__ import annotations

import math

import pytest

from gateway.goby.acomms.buffer import BufferNoDataError, DynamicBuffer, DynamicSubBuffer, merge_configs
from gateway.goby.acomms.protobuf.buffer_pb2 import DynamicBufferConfig as Cfg


def test_merge_rules_only_set_fields_take_part() -> None:
    merged = merge_configs([Cfg(ack_required=False, ttl=10, max_queue=1, blackout_time=5),
                            Cfg(ack_required=True, ttl=30, max_queue=10, blackout_time=2, newest_first=False),
                            Cfg(value_base=50)])
    assert merged.ack_required is True
    assert merged.ttl == 20  # mean of the set values
    assert merged.max_queue == 10  # largest
    assert merged.blackout_time == 2  # smallest
    assert merged.newest_first is False  # only one set it
    assert merged.value_base == 50
    defaults = merge_configs([Cfg()])
    assert (defaults.ttl, defaults.value_base, defaults.max_queue, defaults.newest_first) == (1800, 100, 1000, True)
    assert merge_configs([Cfg(newest_first=False), Cfg(newest_first=True)]).newest_first is True


def test_newest_first_drops_the_oldest_fifo_drops_the_newest() -> None:
    lifo = DynamicSubBuffer([Cfg(max_queue=2)], now=0)
    assert lifo.push(b"a", 1) == [] and lifo.push(b"b", 2) == []
    dropped = lifo.push(b"c", 3)
    assert [v.data for v in dropped] == [b"a"]
    assert lifo.top(4).data == b"c"
    fifo = DynamicSubBuffer([Cfg(max_queue=2, newest_first=False)], now=0)
    fifo.push(b"a", 1)
    fifo.push(b"b", 2)
    assert [v.data for v in fifo.push(b"c", 3)] == [b"c"]
    assert fifo.top(4).data == b"a"


def test_ttl_expiry_from_the_old_end() -> None:
    sub = DynamicSubBuffer([Cfg(ttl=10)], now=0)
    sub.push(b"old", 0)
    sub.push(b"new", 5)
    assert sub.expire(10) == []  # not strictly past ttl yet
    assert [v.data for v in sub.expire(10.5)] == [b"old"]
    assert [v.data for v in sub] == [b"new"]


def test_priority_grows_with_time_since_last_send_and_blackout() -> None:
    sub = DynamicSubBuffer([Cfg(ttl=10, value_base=100, blackout_time=2)], now=0)
    assert sub.top_value(1) == -math.inf  # empty
    sub.push(b"x", 0)
    # creation moved last_access back by the blackout: not in blackout now, value 100 * (1 - (-2)) / 10
    assert sub.top_value(1) == pytest.approx(30)
    sub.top(1)
    sub.push(b"y", 1)
    assert sub.top_value(2.5) == -math.inf  # blackout 2 s after the last send
    assert sub.top_value(3.5) == pytest.approx(25)
    assert sub.top_value(3.5, max_bytes=0) == -math.inf  # does not fit


def test_ack_timeout_holds_a_sent_value_until_it_may_be_resent() -> None:
    sub = DynamicSubBuffer([Cfg(ttl=100)], now=0)
    sub.push(b"x", 0)
    assert sub.top(1, ack_timeout=1).data == b"x"
    assert sub.top_value(1.5, ack_timeout=1) == -math.inf  # awaiting its ack
    assert sub.top_value(2.5, ack_timeout=1) > 0  # eligible again: the retry


def test_contest_picks_the_highest_value_and_infinite_subscriptions_win() -> None:
    buf = DynamicBuffer()
    buf.create(1, "nav", [Cfg(ttl=10, value_base=10)], now=0)
    buf.create(1, "health", [Cfg(ttl=10, value_base=500)], now=0)
    buf.create(2, "sub", [Cfg(ttl=1800, value_base=math.inf, ack_required=True)], now=0)
    buf.push(1, "nav", b"n", 0)
    buf.push(1, "health", b"h", 0)
    buf.push(2, "sub", b"s", 0)
    first = buf.top(5)
    assert (first.dest, first.buffer_id) == (2, "sub")
    assert first.cfg.ack_required
    only_dest_1 = buf.top(5, dest=1)
    assert only_dest_1.buffer_id == "health"
    with pytest.raises(BufferNoDataError):
        buf.top(5, dest=3)
    assert buf.erase(1, "health", only_dest_1.value)
    assert not buf.erase(1, "health", only_dest_1.value)
    assert buf.size() == 2
