"""One thread's interprocess subscriptions and the delivery of received frames to them.

Typed subscriptions are found by their ZeroMQ prefix ``/group/scheme/type/``, regex ones by a full match of group
and type; each frame identifier is validated once (then cached).  No sockets: the interprocess portal reads the
frames and (un)subscribes its SUB socket.  Everything runs on the portal's owning thread, callbacks included (inside
:meth:`FrameDispatcher.deliver`); it logs on the portal's logger, handed in.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from gateway.goby.portal.errors import IdentifierError, MarshallingError
from gateway.goby.portal.identifier import Identifier, decode_frame
from gateway.goby.portal.marshalling import Scheme, parse

if TYPE_CHECKING:
    from gateway.goby.dccl import Codec as DcclCodec

HEAD_CACHE_SIZE = 4096  # distinct identifiers remembered as already validated

RegexCallback = Callable[[bytes, int, str, str], None]


@dataclass(eq=False)
class Subscription:
    msg_type: type
    scheme: int
    callback: Callable[[Any], None]
    echo: bool
    group: str


@dataclass(eq=False)
class RegexSubscription:
    callback: RegexCallback
    group_re: re.Pattern[str]
    type_re: re.Pattern[str]
    schemes: frozenset[int]


class FrameDispatcher:
    """Typed subscriptions by prefix (``subs``), regex ones (``regex``), and the frames that fit neither."""

    def __init__(self, thread_name: str, pid: int, dccl: Callable[[], DcclCodec], log: logging.Logger) -> None:
        self._thread_name = thread_name
        self._pid = pid
        self._dccl = dccl
        self._log = log
        self.subs: dict[bytes, list[Subscription]] = {}
        self.regex: list[RegexSubscription] = []
        self._heads: dict[bytes, tuple[Identifier, bytes]] = {}
        self.malformed = 0

    def split(self, frame: bytes) -> tuple[bytes, Identifier, bytes, bytes] | None:
        """(head, identifier, type prefix, payload) of a frame; None for a malformed one (counted and logged)."""
        nul = frame.find(b"\0")
        if nul < 0:
            self._malformed(frame, "frame has no /group/scheme/type/pid/thread/ identifier followed by NUL")
            return None
        head = frame[:nul]
        known = self._heads.get(head)
        if known is None:  # first frame from this (group, scheme, type, process, thread): validate it once
            try:
                ident, _ = decode_frame(frame)
            except IdentifierError as exc:
                self._malformed(frame, str(exc))
                return None
            cut = head.find(b"/", head.find(b"/", head.find(b"/", 1) + 1) + 1)  # fourth '/'
            known = (ident, head[: cut + 1])
            if len(self._heads) >= HEAD_CACHE_SIZE:
                self._heads.clear()
            self._heads[head] = known
        ident, prefix = known
        return head, ident, prefix, frame[nul + 1:]

    def deliver(self, ident: Identifier, prefix: bytes, payload: bytes) -> None:
        """Call every subscriber of the publication; a callback that raises is logged and the others still run."""
        subs = self.subs.get(prefix)
        if subs:
            own = ident.pid == self._pid
            parsed: dict[type, Any] = {}
            for sub in list(subs):
                if own and not sub.echo:
                    continue
                msg = parsed.get(sub.msg_type)
                if msg is None:
                    try:
                        msg = parse(payload, sub.scheme, sub.msg_type, self._dccl() if sub.scheme == Scheme.DCCL else None)
                    except MarshallingError as exc:
                        self._log.error("%s: cannot decode publication on %s (%s): %s", self._thread_name,
                                        ident.group, ident.type_name, exc)
                        return
                    parsed[sub.msg_type] = msg
                try:
                    sub.callback(msg)
                except Exception:
                    self._log.exception("%s: subscriber callback for %s (%s) raised; continuing", self._thread_name,
                                        ident.group, ident.type_name)
        for rsub in list(self.regex):
            if ((Scheme.ALL_SCHEMES in rsub.schemes or ident.scheme in rsub.schemes)
                    and rsub.type_re.fullmatch(ident.type_name) and rsub.group_re.fullmatch(ident.group)):
                try:
                    rsub.callback(payload, ident.scheme, ident.type_name, ident.group)
                except Exception:
                    self._log.exception("%s: regex subscriber callback raised; continuing", self._thread_name)

    def _malformed(self, frame: bytes, why: str) -> None:
        self.malformed += 1
        if self.malformed > 10 and self.malformed % 1000:
            return  # a flood: log the first ten, then every thousandth (the count says how many)
        self._log.error("%s: dropping malformed frame (%d so far): %s: %r", self._thread_name, self.malformed, why,
                        frame[:80])
