"""The DCCL codec's one error root and its failure kinds, each naming the message, the field and the value."""

from __future__ import annotations

from gateway.errors import GatewayError


class DcclError(GatewayError):
    """Root of every error the DCCL codec raises (a ``GatewayError``)."""


class DefinitionError(DcclError):
    """A message definition DCCL cannot use (``load``): a missing option, bound or codec, or max_bytes exceeded."""

    def __init__(self, message: str, field: str | None, reason: str) -> None:
        where = f"{message}.{field}" if field else message
        super().__init__(f"{where}: {reason}")
        self.message_name = message
        self.field = field
        self.reason = reason


class NotLoadedError(DcclError, KeyError):
    """A message type (or DCCL id) used before ``load``."""

    def __str__(self) -> str:  # KeyError would quote the text
        return str(self.args[0])


class EncodeError(DcclError):
    """A message that cannot be encoded (a required field unset, a value refused in strict mode)."""


class MissingFieldError(EncodeError):
    """Required fields are unset, as protobuf's ``IsInitialized`` reports them."""

    def __init__(self, message: str, fields: list[str]) -> None:
        super().__init__(f"{message} is missing required field(s): {', '.join(fields)}")
        self.message_name = message
        self.fields = fields


class OutOfRangeError(EncodeError):
    """Strict mode: a value outside its field's bounds (or a string/bytes/repeat count too long)."""

    def __init__(self, field: str, value: object, bounds: str) -> None:
        shown = f"{value:g}" if isinstance(value, float) else repr(value) if isinstance(value, str | bytes) else value
        super().__init__(f"{field}={shown} is outside its DCCL bounds {bounds}")
        self.field = field
        self.value = value
        self.bounds = bounds


class DecodeError(DcclError):
    """Bytes that are not a DCCL message of a loaded type."""


class TruncatedError(DecodeError):
    """Fewer bytes than the message needs."""


class UnknownIdError(DecodeError):
    """A DCCL id no loaded message type has."""

    def __init__(self, dccl_id: int) -> None:
        super().__init__(f"DCCL id {dccl_id} has not been loaded (load() the message type first)")
        self.dccl_id = dccl_id


class TrailingBytesError(DecodeError):
    """Bytes left over after one whole message (use ``decode_prefix``/``decode_all`` for packed messages)."""

    def __init__(self, message: str, used: int, total: int) -> None:
        super().__init__(f"{message} uses {used} byte(s) but {total} were given ({total - used} trailing)")
        self.message_name = message
        self.used = used
        self.total = total
