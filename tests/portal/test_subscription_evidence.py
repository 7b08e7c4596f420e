"""What a publishing XPUB knows of subscriptions, on its own (no sockets): live and missing topics, classes of
identifiers, giving up on a topic that does not come back."""

from __future__ import annotations

from gateway.goby.portal.subscription_evidence import (
    LIVE,
    MISSING,
    RESUBSCRIBE_WAIT_S,
    UNTRACKED,
    SubscriptionEvidence,
)

IDENT = "/nav/PROTOBUF/Sample/12/ab/"
LOG_IDENT = "/log/CSTR/CSTR/12/ab/"


def test_a_prefix_subscription_makes_a_topic_live_until_it_is_withdrawn() -> None:
    topics = SubscriptionEvidence()
    assert topics.classify(IDENT) == UNTRACKED
    assert not topics.on_subscription_message(b"\x01/nav/PROTOBUF/Sample/")
    assert topics.classify(IDENT) == LIVE  # the cached class was dropped when the topics changed
    assert topics.classify("/other/PROTOBUF/Sample/12/ab/") == UNTRACKED
    topics.on_subscription_message(b"\x01/")  # a regex subscriber: everything
    topics.on_subscription_message(b"\x00/nav/PROTOBUF/Sample/")
    assert topics.classify("/other/PROTOBUF/Sample/12/ab/") == LIVE
    topics.on_subscription_message(b"\x00/")
    assert topics.classify(IDENT) == UNTRACKED
    assert not topics.on_subscription_message(b"")


def test_after_a_drop_a_topic_is_missing_until_it_subscribes_again() -> None:
    topics = SubscriptionEvidence()
    topics.on_subscription_message(b"\x01/nav/")
    topics.on_subscription_message(b"\x01/log/")
    topics.classify(IDENT), topics.classify(LOG_IDENT)  # we publish on both
    topics.connection_lost()
    topics.on_subscription_message(b"\x00/nav/")  # ZeroMQ withdraws the dead broker's subscriptions
    topics.reconnected(100.0)
    assert topics.classify(IDENT) == MISSING
    assert topics.deadline() == 100.0 + RESUBSCRIBE_WAIT_S
    assert not topics.on_subscription_message(b"\x01/nav/")  # /log/ still missing
    assert topics.classify(IDENT) == LIVE
    assert topics.on_subscription_message(b"\x01/log/")  # the last one back
    assert topics.deadline() is None and topics.give_up(1e9) == []


def test_topics_that_do_not_come_back_are_given_up_after_the_wait() -> None:
    topics = SubscriptionEvidence()
    topics.on_subscription_message(b"\x01/nav/")
    topics.on_subscription_message(b"\x01/log/")
    topics.classify(IDENT), topics.classify(LOG_IDENT)  # we publish on both
    topics.connection_lost()
    topics.on_subscription_message(b"\x00/nav/")
    topics.on_subscription_message(b"\x00/log/")
    topics.reconnected(0.0)
    assert topics.give_up(RESUBSCRIBE_WAIT_S - 0.01) == []
    assert topics.classify(IDENT) == MISSING
    assert topics.give_up(RESUBSCRIBE_WAIT_S) == [b"/log/", b"/nav/"]
    assert topics.classify(IDENT) == UNTRACKED and topics.deadline() is None


def test_only_topics_we_publish_to_wait_after_a_drop() -> None:
    """Other threads' subscriptions (their delivery probes, say) reach our XPUB too: they must not hold us up."""
    topics = SubscriptionEvidence()
    topics.on_subscription_message(b"\x01/nav/")
    topics.on_subscription_message(b"\x01/goby::zeromq::_internal_delivery_probe/CSTR/CSTR/99/cd/")
    topics.classify(IDENT)
    topics.connection_lost()
    topics.reconnected(0.0)
    assert topics.missing == {b"/nav/"}
    assert topics.on_subscription_message(b"\x01/nav/")  # the only one we wait for
