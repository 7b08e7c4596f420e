"""Goby3's ``.goby`` log format (version 3): the entry codec, a writer that writes what goby_logger writes, a
reader that resynchronises after damage, and the renderings goby_log_tool produces.  See docs/logging.md."""

from gateway.goby.log.descriptors import FILE_DESCRIPTOR_GROUP, FILE_DESCRIPTOR_TYPE, LogDescriptorPool
from gateway.goby.log.entry import CURRENT_VERSION, MAGIC, LogEntry, SkippedSpan, encode_record
from gateway.goby.log.errors import LogError, LogFormatError, LogWriteError, NewerVersionError
from gateway.goby.log.reader import LogReader
from gateway.goby.log.render import Decoded, EntryDecoder, debug_text_line, json_objects
from gateway.goby.log.writer import LogWriter

__all__ = [
    "CURRENT_VERSION",
    "FILE_DESCRIPTOR_GROUP",
    "FILE_DESCRIPTOR_TYPE",
    "MAGIC",
    "Decoded",
    "EntryDecoder",
    "LogDescriptorPool",
    "LogEntry",
    "LogError",
    "LogFormatError",
    "LogReader",
    "LogWriteError",
    "LogWriter",
    "NewerVersionError",
    "SkippedSpan",
    "debug_text_line",
    "encode_record",
    "json_objects",
]
