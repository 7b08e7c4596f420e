"""DCCL validity for the USV command path: exactly what the DCCL codec accepts, with messages naming the field.

Why: DCCL sends an out-of-range optional field as "not set" without a word, so a USVCommand with radius 5000
would reach the USV as a polygon of radius 0. We refuse such commands before anything reaches MOOS by encoding
them with the DCCL codec in strict mode: one definition of "valid", the codec's, read from the message's own
``(dccl.field)`` options. A value inside the bounds but off the step (radius 304 with 10 m steps) is sent as DCCL
rounds it (300), with a notice.
"""

from __future__ import annotations

import logging
from typing import TypeVar

from google.protobuf.message import Message

from gateway.goby.dccl import Codec, DcclError
from gateway.goby.portal.marshalling import is_dccl
from translators.errors import TranslatorError
from util.descriptors import descriptor_of, initialization_errors

log = logging.getLogger(__name__)


class DcclBoundsError(TranslatorError, ValueError):
    """A message that DCCL could not carry as given: a field outside its bounds, or a required field unset."""


M = TypeVar("M", bound=Message)


def check_dccl_bounds(msg: M, notices: list[str] | None = None, codec: Codec | None = None) -> M:
    """A copy of ``msg`` as DCCL would deliver it, or :class:`DcclBoundsError` if DCCL could not deliver it.

    Each value DCCL would round to its step is rounded in the copy, and a line saying so is appended to
    ``notices`` (and logged). Time stamps (``dccl.time2`` fields) keep the sender's value: DCCL sends whole
    seconds, but on interprocess the stamp also identifies the command's acknowledgements. ``codec``: an
    application's DCCL codec (``context.dccl``), which keeps the compiled type; by default a new one is made
    (a few milliseconds). The check is a strict encode whatever the codec's own setting. A message type without
    DCCL options is only checked for its required fields.
    """
    if not is_dccl(type(msg)):  # no (dccl.msg) options: DCCL never carries it, only protobuf's rules apply
        missing = initialization_errors(msg)
        if missing:
            raise DcclBoundsError(f"{descriptor_of(msg).full_name} is missing required field(s): {', '.join(missing)}")
        copy = type(msg)()
        copy.CopyFrom(msg)
        return copy
    codec = codec if codec is not None else Codec()
    try:
        codec.load(type(msg))
        delivered = codec.decode(codec.encode(msg, strict=True))
    except DcclError as error:
        raise DcclBoundsError(str(error)) from None
    assert isinstance(delivered, type(msg))  # the codec decodes into the class it loaded
    bounds = {b.name: b for b in codec.bounds(type(msg))}
    for field, value in msg.ListFields():
        spec = bounds.get(field.name)
        if spec is None or field.is_repeated or field.message_type is not None:
            continue
        if spec.time:
            setattr(delivered, field.name, value)
            continue
        sent = getattr(delivered, field.name)
        if sent != value:
            notice = f"{msg.DESCRIPTOR.name}.{field.name}={value} is sent as {sent} (DCCL: {spec.describe()})"
            log.info("%s", notice)
            if notices is not None:
                notices.append(notice)
    return delivered
