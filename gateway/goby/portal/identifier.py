"""Goby3 wire identifiers: ``/group/scheme/type/pid/thread/`` + NUL + payload, one ZeroMQ frame per publication.

Pure functions of bytes; no sockets here.  Subscriptions are ZeroMQ prefix filters on the
``/group/scheme/type/`` form, so a subscriber receives every process and thread that publishes that triple.
"""

from __future__ import annotations

import os
import threading
import zlib
from dataclasses import dataclass

from gateway.goby.portal.errors import IdentifierError
from gateway.goby.portal.marshalling import scheme_from_string, scheme_to_string

#: Prefix matching every publication (regex subscriptions subscribe with it).
EVERYTHING = b"/"


def thread_id(ident: int | None = None) -> str:
    """Lowercase hex (no ``0x``, at most 16 digits) naming the calling thread, as Goby's ``thread_id()``.

    Goby prints a hash of ``std::thread::id``; we print a hash of Python's thread ident, which is just as opaque.
    """
    value = threading.get_ident() if ident is None else ident
    return format(zlib.crc32(value.to_bytes(8, "little")) << 32 | (value & 0xFFFFFFFF), "x")


def type_prefix(group: str, scheme: int, type_name: str) -> str:
    """PROCESS_THREAD_WILDCARD form: the subscription filter for one (group, scheme, type)."""
    return f"/{group}/{scheme_to_string(scheme)}/{type_name}/"


def make_identifier(group: str, scheme: int, type_name: str, pid: int | None = None, thread: str | None = None) -> str:
    """NO_WILDCARDS form: what a publication carries."""
    pid = os.getpid() if pid is None else pid
    thread = thread_id() if thread is None else thread
    return f"{type_prefix(group, scheme, type_name)}{pid}/{thread}/"


def encode_frame(identifier: str, payload: bytes) -> bytes:
    """One publication frame: identifier, NUL, payload."""
    return identifier.encode() + b"\0" + payload


@dataclass(frozen=True, slots=True)
class Identifier:
    """The parts of a received identifier."""

    group: str
    scheme: int
    type_name: str
    pid: int
    thread: int

    @property
    def prefix(self) -> bytes:
        """The subscription filter that matches this publication."""
        return type_prefix(self.group, self.scheme, self.type_name).encode()


def decode_frame(frame: bytes) -> tuple[Identifier, bytes]:
    """Split a received frame into its identifier and payload; ``IdentifierError`` names what is wrong."""
    nul = frame.find(b"\0")
    if nul < 0:
        raise IdentifierError(f"frame has no NUL after its identifier: {frame[:80]!r}")
    head = frame[:nul]
    try:
        text = head.decode()
    except UnicodeDecodeError:
        raise IdentifierError(f"identifier is not UTF-8: {head[:80]!r}") from None
    parts = text.split("/")
    # "/g/s/t/p/th/" splits into ['', g, s, t, p, th, '']
    if len(parts) != 7 or parts[0] or parts[6]:
        raise IdentifierError(f"identifier does not have the form /group/scheme/type/pid/thread/: {text!r}")
    _, group, scheme_text, type_name, pid_text, thread_text, _ = parts
    try:
        scheme = scheme_from_string(scheme_text)
        pid = int(pid_text)
        thread = int(thread_text, 16)
    except Exception as exc:  # noqa: BLE001 - any parse failure is a malformed identifier
        raise IdentifierError(f"malformed identifier {text!r}: {exc}") from None
    if len(thread_text) > 16:
        raise IdentifierError(f"thread id longer than 16 hex digits in {text!r}")
    return Identifier(group, scheme, type_name, pid, thread), frame[nul + 1 :]
