"""The commander's state: the command types a page may send, where to, and the log of sent commands.

Threads: everything here runs on the web thread.  The portal thread reports publications, acks and expiries by
scheduling :meth:`CommanderModel.published`, :meth:`acknowledged` and :meth:`expired` on the web loop
(``loop.call_soon_threadsafe``), so no lock is needed.
"""

from __future__ import annotations

import itertools
import re
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from google.protobuf import text_format
from google.protobuf.message import Message

from gateway.goby.portal.group import Group
from gateway.goby.protobuf.layer_pb2 import LAYER_INTERVEHICLE, Layer
from launch.liaison.form_schema import message_schema
from launch.liaison.protobuf.liaison_web_pb2 import InterProcessAck
from util.descriptors import descriptor_of

#: Sent, then one of the final states.
SENDING, SENT, ACKNOWLEDGED, REFUSED, EXPIRED, FAILED = "sending", "sent", "acknowledged", "refused", "expired", "failed"

# AckData / ExpireData's ``latency`` (int64, microseconds by its DCCL units) in their text form; not ``link_latency``.
LINK_REPORTS = ("Ack: ", "Expire: ")  # how portal_side prefixes the link's AckData / ExpireData texts
_LATENCY_US = re.compile(r"(?<![\w.])latency: (-?\d+)(?![\w.])")


def latency_text(microseconds: int) -> str:
    """A link latency with its unit: ``850.2 ms`` below a second, ``2.378 s`` from there."""
    if abs(microseconds) < 1_000_000:
        return f"{microseconds / 1e3:.1f} ms"
    return f"{microseconds / 1e6:.3f} s"


def with_latency_unit(text: str) -> str:
    """A link's ack or expiry text (``Ack: header {...} latency: 2378143``, ``Expire: ...``) with the latency in ms
    or s, as ``latency: 2.378 s``: the field is microseconds (its DCCL units), which a bare number does not say.
    Other texts (an interprocess ack message, whose fields mean what their type says) are returned as they are."""
    if not text.startswith(LINK_REPORTS):
        return text
    return _LATENCY_US.sub(lambda m: f"latency: {latency_text(int(m.group(1)))}", text)


def layer_text(layer: Layer.ValueType) -> str:
    """Goby's ``to_string(Layer)``: the enum name without ``LAYER_``, lower case."""
    return Layer.Name(layer).removeprefix("LAYER_").lower()


@dataclass(frozen=True)
class Target:
    """One ``publish_to`` entry: where a command type may be sent."""

    index: int
    group: str
    numeric: int
    numeric_field: str
    layer: Layer.ValueType

    @property
    def label(self) -> str:
        """As Goby shows it: ``group [interprocess]``, ``group/0 [intervehicle]``, ``group/{field} [...]``."""
        if self.layer == LAYER_INTERVEHICLE:
            numeric = f"{{{self.numeric_field}}}" if self.numeric_field else str(self.numeric)
            return f"{self.group}/{numeric} [{layer_text(self.layer)}]"
        return f"{self.group} [{layer_text(self.layer)}]"

    def group_for(self, msg: Message) -> Group:
        """The group a message goes to (intervehicle: numeric from the configured field, as Goby)."""
        if self.layer != LAYER_INTERVEHICLE:
            return Group.parse(self.group)
        numeric = int(getattr(msg, self.numeric_field)) if self.numeric_field else self.numeric
        return Group(self.group, numeric)


@dataclass(frozen=True)
class CommandType:
    """A type the commander offers, its form and its targets."""

    name: str
    cls: type[Message]
    targets: tuple[Target, ...]
    ack: InterProcessAck | None = None

    def view(self) -> dict[str, Any]:
        return {"name": self.name, "schema": message_schema(descriptor_of(self.cls)),
                "targets": [{"index": t.index, "label": t.label, "layer": layer_text(t.layer)} for t in self.targets]}


@dataclass(eq=False)
class SentCommand:
    """One command sent from a page, and what became of it."""

    id: int
    type_name: str
    target: str
    text: str
    time: float  # application clock, seconds
    address: str
    comment: str
    expires_at: float | None  # monotonic; None: wait for the layer's own expiry
    match_value: Any = None
    state: str = SENDING
    acks: list[str] = field(default_factory=list)
    error: str = ""

    def view(self) -> dict[str, Any]:
        return {"id": self.id, "type": self.type_name, "target": self.target, "text": self.text, "time": self.time,
                "address": self.address, "comment": self.comment, "state": self.state, "acks": list(self.acks),
                "error": self.error}


class CommanderModel:
    """Command types by name, and the last ``history_size`` sent commands (newest last)."""

    def __init__(self, types: list[CommandType], history_size: int = 200) -> None:
        self.types = {t.name: t for t in types}
        self.history: deque[SentCommand] = deque(maxlen=max(1, history_size))
        self._ids = itertools.count(1)

    def catalogue(self) -> list[dict[str, Any]]:
        """Every command type with its form schema and targets, sorted by name (Goby sorts its combo box)."""
        return [self.types[name].view() for name in sorted(self.types)]

    def record(self, kind: CommandType, target: Target, msg: Message, address: str, comment: str,
               now: float) -> SentCommand:
        """Log a command about to be published; returns its entry (state ``sending``)."""
        expires_at = None
        match_value = None
        if kind.ack is not None and target.layer != LAYER_INTERVEHICLE:
            expires_at = time.monotonic() + kind.ack.timeout
            match_value = getattr(msg, kind.ack.command_field)
        text = text_format.MessageToString(msg, as_one_line=True)
        entry = SentCommand(next(self._ids), kind.name, target.label, text, now, address,
                            comment or f"[{text[:100]}{'...' if len(text) > 100 else ''}]", expires_at, match_value)
        self.history.append(entry)
        return entry

    def find(self, entry_id: int) -> SentCommand | None:
        return next((e for e in self.history if e.id == entry_id), None)

    def published(self, entry_id: int, error: str | None) -> SentCommand | None:
        """The portal thread published (or could not: ``error``)."""
        entry = self.find(entry_id)
        if entry is not None and entry.state == SENDING:
            entry.state = FAILED if error else SENT
            entry.error = error or ""
        return entry

    def acknowledged(self, entry_id: int, text: str, final: bool = True, refused: bool = False) -> SentCommand | None:
        """An acknowledgement of one command (intervehicle: the link's ack)."""
        entry = self.find(entry_id)
        if entry is None:
            return None
        entry.acks.append(with_latency_unit(text))
        if refused:
            entry.state = REFUSED
        elif final and entry.state in (SENDING, SENT, EXPIRED):
            entry.state = ACKNOWLEDGED
        return entry

    def interprocess_ack(self, type_name: str, value: Any, text: str, final: bool,
                         refused: bool) -> SentCommand | None:
        """An ack message on interprocess: it belongs to the newest command of ``type_name`` whose match value is
        ``value``; None if no command matches (someone else's command)."""
        for entry in reversed(self.history):
            if entry.type_name == type_name and entry.match_value == value and entry.expires_at is not None:
                return self.acknowledged(entry.id, text, final, refused)
        return None

    def expired(self, entry_id: int, text: str) -> SentCommand | None:
        """The layer gave up on a command (intervehicle expiry)."""
        entry = self.find(entry_id)
        if entry is not None and entry.state in (SENDING, SENT):
            entry.state = EXPIRED
            entry.acks.append(with_latency_unit(text))
        return entry

    def expire_due(self, now: float) -> list[SentCommand]:
        """Commands whose interprocess ack did not come in time (``now``: monotonic)."""
        due = []
        for entry in self.history:
            if entry.state == SENT and entry.expires_at is not None and now >= entry.expires_at:
                entry.state = EXPIRED
                entry.acks.append("no acknowledgement within the timeout")
                due.append(entry)
        return due
