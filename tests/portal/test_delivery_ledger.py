"""The delivery ledger on its own (no sockets): which publications a probe confirms, when probes are due, what is
reported in doubt when the connection drops."""

from __future__ import annotations

from gateway.goby.portal.delivery_ledger import PROBE_AGE_S, PROBE_BATCH, PROBE_RETRY_S, DeliveryLedger


def _record(ledger: DeliveryLedger, numbers: range, now: float = 0.0) -> list[bool]:
    return [ledger.record("g", str(n).encode(), now) for n in numbers]


def test_a_probe_is_due_after_a_batch_and_confirms_only_what_went_before_it() -> None:
    ledger = DeliveryLedger()
    due = _record(ledger, range(PROBE_BATCH))
    assert due == [False] * (PROBE_BATCH - 1) + [True]
    first = ledger.next_probe()
    ledger.probe_sent(0.0)
    assert not any(_record(ledger, range(PROBE_BATCH, PROBE_BATCH + 3)))  # one probe in flight at a time
    second = ledger.next_probe()
    assert first != second
    assert not ledger.confirm(first, 0.01)  # 3 left, young, no probe out: nothing due yet
    assert len(ledger) == 3
    assert ledger.in_doubt() == [("g", str(n).encode()) for n in range(PROBE_BATCH, PROBE_BATCH + 3)]
    assert len(ledger) == 0 and ledger.deadline() is None


def test_an_old_publication_makes_a_probe_due_and_an_unanswered_probe_is_retried() -> None:
    ledger = DeliveryLedger()
    _record(ledger, range(1), now=0.0)
    assert not ledger.probe_due(PROBE_AGE_S / 2)
    assert ledger.deadline() == PROBE_AGE_S
    assert ledger.probe_due(PROBE_AGE_S)
    ledger.next_probe()
    ledger.probe_not_sent(1.0)  # e.g. our probe subscription not through yet
    assert not ledger.probe_due(1.0 + PROBE_RETRY_S / 2)
    assert ledger.deadline() == 1.0 + PROBE_RETRY_S and ledger.probe_due(1.0 + PROBE_RETRY_S)


def test_unknown_stale_and_garbled_probes_confirm_nothing() -> None:
    ledger = DeliveryLedger()
    _record(ledger, range(2))
    stale = ledger.next_probe()
    ledger.probe_sent(0.0)
    assert ledger.in_doubt() == [("g", b"0"), ("g", b"1")]  # the connection dropped: probes in flight forgotten
    _record(ledger, range(2, 4))
    for payload in (stale, b"x\0", b"999\0", b""):
        assert not ledger.confirm(payload, 0.0)
    assert len(ledger) == 2


def test_a_later_probe_confirms_past_a_lost_one_and_a_newer_one_stays_pending() -> None:
    ledger = DeliveryLedger()
    _record(ledger, range(2))
    lost = ledger.next_probe()
    ledger.probe_sent(0.0)
    _record(ledger, range(2, 4))
    later = ledger.next_probe()
    ledger.probe_sent(1.0)
    _record(ledger, range(4, 5))
    assert ledger.confirm(later, 1.0 + PROBE_AGE_S)  # the one left is old enough: another probe is due
    assert ledger.in_doubt() == [("g", b"4")]
    assert not ledger.confirm(lost, 2.0)  # dropped when the later one came back


def test_beyond_the_cap_the_oldest_are_assumed_delivered() -> None:
    ledger = DeliveryLedger(max_unconfirmed=3)
    _record(ledger, range(5))
    assert ledger.assumed_delivered == 2
    assert [payload for _, payload in ledger.in_doubt()] == [b"2", b"3", b"4"]
