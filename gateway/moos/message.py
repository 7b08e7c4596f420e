"""``MoosMessage``: one CMOOSMsg, with pymoos's accessor names.

Fields hold the raw wire bytes (MOOS strings carry no encoding); accessors decode them as UTF-8 and keep
undecodable bytes via ``surrogateescape``, so ``str`` values round-trip to the same bytes.
"""

from __future__ import annotations

# Message types (CMOOSMsg::m_cMsgType), as the single wire byte.
NOTIFY = b"N"
REGISTER = b"R"
UNREGISTER = b"U"
WILDCARD_REGISTER = b"*"
WILDCARD_UNREGISTER = b"/"
NOT_SET = b"~"
COMMAND = b"C"
ANONYMOUS = b"A"
NULL_MSG = b"."
DATA = b"i"
POISON = b"K"
WELCOME = b"W"
SERVER_REQUEST = b"Q"
TIMING = b"T"
TERMINATE = b"^"

# Data types (CMOOSMsg::m_cDataType).
DOUBLE = b"D"
STRING = b"S"
BINARY = b"B"

SERVER_REQUEST_ID = -2
ASYNC_KEY = b"asynchronous"
TIMING_KEY = b"_async_timing"


def to_bytes(text: str | bytes) -> bytes:
    """Encode a MOOS string field: UTF-8, with surrogate-escaped bytes restored as they were."""
    if isinstance(text, bytes):
        return text
    return text.encode("utf-8", "surrogateescape")


def to_str(raw: bytes) -> str:
    """Decode a MOOS string field without ever failing (the inverse of :func:`to_bytes`)."""
    return raw.decode("utf-8", "surrogateescape")


class MoosMessage:
    """A CMOOSMsg. Attributes are the wire fields; methods are pymoos's ``moos_msg`` accessors."""

    __slots__ = (
        "msg_type",
        "data_type",
        "msg_id",
        "raw_src",
        "raw_aux",
        "raw_community",
        "raw_key",
        "msg_time",
        "dval",
        "dval2",
        "raw_sval",
    )

    def __init__(
        self,
        msg_type: bytes = NULL_MSG,
        data_type: bytes = DOUBLE,
        msg_id: int = -1,
        src: bytes = b"",
        aux: bytes = b"",
        community: bytes = b"",
        key: bytes = b"",
        msg_time: float = -1.0,
        dval: float = -1.0,
        dval2: float = -1.0,
        sval: bytes = b"",
    ) -> None:
        self.msg_type = msg_type
        self.data_type = data_type
        self.msg_id = msg_id
        self.raw_src = src
        self.raw_aux = aux
        self.raw_community = community
        self.raw_key = key
        self.msg_time = msg_time
        self.dval = dval
        self.dval2 = dval2
        self.raw_sval = sval

    # ---- constructors mirroring CMOOSMsg's --------------------------------------------------------
    @classmethod
    def double_msg(cls, msg_type: bytes, key: str | bytes, value: float, msg_time: float) -> MoosMessage:
        """A double-valued message, as ``CMOOSMsg(type, key, double, time)``."""
        return cls(msg_type, DOUBLE, key=to_bytes(key), msg_time=msg_time, dval=float(value))

    @classmethod
    def string_msg(cls, msg_type: bytes, key: str | bytes, value: str | bytes, msg_time: float) -> MoosMessage:
        """A string-valued message, as ``CMOOSMsg(type, key, string, time)``."""
        return cls(msg_type, STRING, key=to_bytes(key), msg_time=msg_time, sval=to_bytes(value))

    @classmethod
    def binary_msg(cls, msg_type: bytes, key: str | bytes, value: bytes, msg_time: float) -> MoosMessage:
        """A binary message: a string message marked as binary (``MarkAsBinary``)."""
        return cls(msg_type, BINARY, key=to_bytes(key), msg_time=msg_time, sval=bytes(value))

    def copy(self) -> MoosMessage:
        """A shallow copy (all fields are immutable values)."""
        return MoosMessage(
            self.msg_type, self.data_type, self.msg_id, self.raw_src, self.raw_aux, self.raw_community,
            self.raw_key, self.msg_time, self.dval, self.dval2, self.raw_sval,
        )

    # ---- pymoos accessors ---------------------------------------------------------------------------
    def key(self) -> str:
        return to_str(self.raw_key)

    def name(self) -> str:
        return to_str(self.raw_key)

    def is_name(self, name: str) -> bool:
        return self.raw_key == to_bytes(name)

    def source(self) -> str:
        return to_str(self.raw_src)

    def source_aux(self) -> str:
        return to_str(self.raw_aux)

    def community(self) -> str:
        return to_str(self.raw_community)

    def time(self) -> float:
        return self.msg_time

    def is_double(self) -> bool:
        return self.data_type == DOUBLE

    def is_string(self) -> bool:
        """True for string *and* binary messages, as in C++ ``IsString()``."""
        return self.data_type == STRING or self.data_type == BINARY

    def is_binary(self) -> bool:
        return self.data_type == BINARY

    def double(self) -> float:
        return self.dval

    def double_aux(self) -> float:
        return self.dval2

    def string(self) -> str:
        return to_str(self.raw_sval)

    def binary_data(self) -> bytes:
        return self.raw_sval

    def binary_data_size(self) -> int:
        return len(self.raw_sval)

    def mark_as_binary(self) -> None:
        self.data_type = BINARY

    def type(self) -> str:
        """The message type character (``'N'``, ``'R'``, ...)."""
        return self.msg_type.decode("latin-1")

    def is_type(self, msg_type: str) -> bool:
        return self.msg_type == msg_type.encode("latin-1")

    def trace(self) -> None:
        """Print a one-line description, like ``CMOOSMsg::Trace``."""
        print(self.describe())

    def describe(self) -> str:
        """A human-readable one-line summary (used by logs and ``trace``)."""
        if self.data_type == DOUBLE:
            value = repr(self.dval)
        elif self.data_type == BINARY:
            value = f"<{len(self.raw_sval)} bytes>"
        else:
            value = repr(self.string())
        return (
            f"type={self.type()} data={self.data_type.decode('latin-1')} id={self.msg_id} key={self.key()!r} "
            f"src={self.source()!r} aux={self.source_aux()!r} community={self.community()!r} "
            f"time={self.msg_time:.6f} value={value}"
        )

    def __repr__(self) -> str:
        return f"MoosMessage({self.describe()})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, MoosMessage):
            return NotImplemented
        return all(getattr(self, f) == getattr(other, f) for f in self.__slots__)

    __hash__ = None  # type: ignore[assignment]  # mutable
