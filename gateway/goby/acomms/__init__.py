"""Goby3's acomms layer in Python: the DynamicBuffer, the TDMA MAC, the modem driver ABC and its drivers
(an in-process "ether" and Goby's UDP multicast driver). See docs/intervehicle.md."""

from gateway.goby.acomms.buffer import BufferNoDataError, DynamicBuffer, DynamicSubBuffer, merge_configs
from gateway.goby.acomms.errors import AcommsError, ModemConfigError, ModemDriverError

__all__ = [
    "AcommsError",
    "BufferNoDataError",
    "DynamicBuffer",
    "DynamicSubBuffer",
    "ModemConfigError",
    "ModemDriverError",
    "merge_configs",
]
