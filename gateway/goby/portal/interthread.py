"""In-process publish/subscribe between threads (Goby's InterThreadTransporter).

No serialization: the published object itself is handed to each subscribing thread, so do not mutate a message
after publishing it.  Each subscriber's callback runs on the subscribing thread, queued through its
:class:`~gateway.goby.portal.mailbox.Mailbox`; order is kept per subscriber.  The publishing thread does not receive
its own publication unless ``echo=True`` (Goby's default is no echo on interthread).
"""

from __future__ import annotations

import re
import threading
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from google.protobuf import message as pb_message

from gateway.goby.portal.errors import ClosedError
from gateway.goby.portal.group import GroupLike, as_group, check_named
from gateway.goby.portal.interface_registry import InterfaceEntry, InterfaceRegistry
from gateway.goby.portal.marshalling import Scheme
from util.reactor import Mailbox

LAYER = "interthread"


def type_key(msg_type: type) -> str:
    """How interthread names a type: protobuf full name, ``CSTR`` for str, else ``module.QualName``."""
    if issubclass(msg_type, pb_message.Message):
        return msg_type.DESCRIPTOR.full_name
    if issubclass(msg_type, str):
        return "CSTR"
    return f"{msg_type.__module__}.{msg_type.__qualname__}"


@dataclass(eq=False)
class _Subscription:
    mailbox: Mailbox
    callback: Callable[[Any], None]


@dataclass(eq=False)
class _RegexSubscription:
    mailbox: Mailbox
    callback: Callable[[Any, int, str, str], None]
    group_re: re.Pattern[str]
    type_re: re.Pattern[str]
    schemes: frozenset[int] = field(default_factory=frozenset)


class InterThread:
    """The process-wide interthread hub; threads use it through an :class:`InterThreadTransporter`."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._subs: dict[tuple[str, str], list[_Subscription]] = {}
        self._regex: list[_RegexSubscription] = []

    def add(self, group: str, key: str, sub: _Subscription) -> None:
        with self._lock:
            self._subs.setdefault((group, key), []).append(sub)

    def add_regex(self, sub: _RegexSubscription) -> None:
        with self._lock:
            self._regex.append(sub)

    def remove(self, mailbox: Mailbox, group: str | None = None, key: str | None = None) -> None:
        """Drop ``mailbox``'s subscriptions (all of them when group/key are None)."""
        with self._lock:
            for sub_key in list(self._subs):
                if group is not None and sub_key != (group, key):
                    continue
                kept = [s for s in self._subs[sub_key] if s.mailbox is not mailbox]
                if kept:
                    self._subs[sub_key] = kept
                else:
                    del self._subs[sub_key]
            if group is None:
                self._regex = [r for r in self._regex if r.mailbox is not mailbox]

    def deliver(self, group: str, key: str, msg: Any, publisher: Mailbox | None, echo: bool = False) -> int:
        """Queue ``msg`` to every subscriber of (group, key); returns how many threads it was queued to."""
        targets = self._subs.get((group, key))
        regexes = self._regex
        count = 0
        if targets:
            for sub in list(targets):
                if sub.mailbox is publisher and not echo:
                    continue
                try:
                    sub.mailbox.post(sub.callback, msg)
                    count += 1
                except ClosedError:
                    pass  # the subscribing thread has just ended
        for rsub in list(regexes):
            if rsub.mailbox is publisher and not echo:
                continue
            if _regex_matches(rsub, Scheme.CXX_OBJECT, key, group):
                try:
                    rsub.mailbox.post(rsub.callback, msg, int(Scheme.CXX_OBJECT), key, group)
                    count += 1
                except ClosedError:
                    pass
        return count


def _regex_matches(sub: _RegexSubscription, scheme: int, type_name: str, group: str) -> bool:
    schemes_ok = not sub.schemes or Scheme.ALL_SCHEMES in sub.schemes or scheme in sub.schemes
    return bool(schemes_ok and sub.type_re.fullmatch(type_name) and sub.group_re.fullmatch(group))


class InterThreadTransporter:
    """One thread's handle on the interthread layer; every method must be called from the owning thread."""

    def __init__(
        self, hub: InterThread, mailbox: Mailbox, thread_name: str, registry: InterfaceRegistry, application: str = "",
    ) -> None:
        self._hub = hub
        self._mailbox = mailbox
        self._thread_name = thread_name
        self._registry = registry
        self._application = application
        self._recorded: set[tuple[str, str, str]] = set()

    def _record(self, direction: str, group: str, key: str) -> None:
        if (direction, group, key) in self._recorded:
            return
        self._recorded.add((direction, group, key))
        self._registry.record(
            InterfaceEntry(LAYER, direction, group, Scheme.CXX_OBJECT.name, key, self._thread_name, self._application)
        )

    def publish(self, group: GroupLike, msg: Any, *, echo: bool = False) -> None:
        """Hand ``msg`` to every thread subscribed to (group, type of msg)."""
        grp = as_group(group)
        check_named(grp, "InterThread")
        key = type_key(type(msg))
        self._record("publish", str(grp), key)
        self._hub.deliver(str(grp), key, msg, self._mailbox, echo)

    def subscribe(self, group: GroupLike, msg_type: type, callback: Callable[[Any], None]) -> None:
        """Call ``callback(msg)`` on this (the subscribing) thread for each ``msg_type`` published on ``group``."""
        grp = as_group(group)
        check_named(grp, "InterThread")
        key = type_key(msg_type)
        self._record("subscribe", str(grp), key)
        self._hub.add(str(grp), key, _Subscription(self._mailbox, callback))

    def subscribe_regex(
        self,
        callback: Callable[[Any, int, str, str], None],
        group_regex: str = ".*",
        type_regex: str = ".*",
        schemes: Iterable[int] = (Scheme.ALL_SCHEMES,),
    ) -> None:
        """Call ``callback(obj, scheme, type_name, group)`` on this thread for every publication whose group and type
        fully match the regexes (scheme is CXX_OBJECT here)."""
        self._record("subscribe", f"regex:{group_regex}", f"regex:{type_regex}")
        self._hub.add_regex(
            _RegexSubscription(self._mailbox, callback, re.compile(group_regex), re.compile(type_regex),
                               frozenset(int(s) for s in schemes))
        )

    def unsubscribe(self, group: GroupLike, msg_type: type) -> None:
        """Remove this thread's subscriptions to (group, msg_type)."""
        self._hub.remove(self._mailbox, str(as_group(group)), type_key(msg_type))

    def unsubscribe_all(self) -> None:
        """Remove every subscription of this thread (done automatically when the thread ends)."""
        self._hub.remove(self._mailbox)
