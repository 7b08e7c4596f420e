"""The .goby byte layout, the writer's index and descriptor entries, and the reader on damaged logs.

Golden data: ``data/real_goby_logger_3.1.5.goby`` was written by the real goby_logger (Goby3 3.1.5a, gobyd and
goby_logger only: their manager handshake and the logger's configuration), ``.txt`` is the real goby_log_tool's
DEBUG_TEXT of it.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Callable
from pathlib import Path

import pytest

from gateway.goby.log import (
    FILE_DESCRIPTOR_GROUP,
    FILE_DESCRIPTOR_TYPE,
    EntryDecoder,
    LogFormatError,
    LogReader,
    LogWriter,
    NewerVersionError,
    bson,
    debug_text_line,
)
from gateway.goby.log.descriptors import file_descriptor_bytes
from gateway.goby.log.render import json_objects
from gateway.goby.portal import Scheme
from tests.protobuf.sample_messages_pb2 import Sample

DATA = Path(__file__).parent / "data"
T0 = 1_795_859_707_386_269


def ticking_clock(start: int = T0) -> Callable[[], int]:
    now = [start]

    def clock() -> int:
        now[0] += 1
        return now[0]

    return clock


def record(scheme: int, group: int, type_: int, ts: int, data: bytes) -> bytes:
    """An entry built from the layout in Goby3's log_entry.h, independently of the writer."""
    body = struct.pack(">HHHQ", scheme, group, type_, ts) + data
    head = b"GBY3" + struct.pack(">I", len(body) + 4)
    return head + body + struct.pack(">I", zlib.crc32(head + body))


def sample_log() -> bytes:
    out = bytearray()
    writer = LogWriter(out.extend, ticking_clock(), describe_protobuf=False)
    writer.write(b"one\0", Scheme.CSTR, "CSTR", "text", T0)
    writer.write(Sample(a=1).SerializeToString(), Scheme.PROTOBUF, "goby.test.zeromq.protobuf.Sample", "nav", T0 + 1)
    writer.write(b"two\0", Scheme.CSTR, "CSTR", "text", T0 + 2)
    writer.write(bson.encode({"x": 1, "s": "y"}), Scheme.JSON, "nlohmann::json", "json", T0 + 3)
    writer.write(b"three\0", Scheme.CSTR, "CSTR", "text", T0 + 4)
    return bytes(out)


def test_writer_bytes_follow_goby_layout() -> None:
    out = bytearray()
    writer = LogWriter(out.extend, ticking_clock(), describe_protobuf=False)
    writer.write(b"hi\0", Scheme.CSTR, "CSTR", "g1", T0)
    writer.write(b"yo\0", Scheme.CSTR, "CSTR", "g2", T0 + 5)
    writer.write(b"x", Scheme.PROTOBUF, "T", "g1", T0 + 9)  # same group name, other scheme: a new group index
    expected = (struct.pack(">I", 3)
                + record(0xFFFF, 1, 0, T0, b"\x00\x00g1") + record(0xFFFE, 0, 1, T0, b"\x00\x00CSTR")
                + record(0, 1, 1, T0, b"hi\0")
                + record(0xFFFF, 2, 0, T0 + 5, b"\x00\x00g2") + record(0, 2, 1, T0 + 5, b"yo\0")
                + record(0xFFFF, 3, 0, T0 + 9, b"\x00\x01g1") + record(0xFFFE, 0, 2, T0 + 9, b"\x00\x01T")
                + record(1, 3, 2, T0 + 9, b"x"))
    assert bytes(out) == expected


def test_protobuf_types_bring_their_file_descriptors_first() -> None:
    out = bytearray()
    writer = LogWriter(out.extend, ticking_clock())
    writer.write(Sample(a=5).SerializeToString(), Scheme.PROTOBUF, Sample.DESCRIPTOR.full_name, "nav")
    writer.write(Sample(a=6).SerializeToString(), Scheme.PROTOBUF, Sample.DESCRIPTOR.full_name, "nav")
    entries = list(LogReader(bytes(out), include_descriptors=True))
    names = [e.group for e in entries]
    first_data = names.index("nav")
    assert set(names[:first_data]) == {FILE_DESCRIPTOR_GROUP} and names[first_data:] == ["nav", "nav"]
    files = [e.data for e in entries[:first_data]]
    assert all(e.type_name == FILE_DESCRIPTOR_TYPE for e in entries[:first_data])
    # the type's own file comes after every file it imports, and FileDescriptorProto's own file is there too
    assert files.index(file_descriptor_bytes(Sample.DESCRIPTOR.file)) == len(files) - 1
    assert file_descriptor_bytes(Sample.DESCRIPTOR.file.dependencies[0]) in files
    from google.protobuf import descriptor_pb2

    assert file_descriptor_bytes(descriptor_pb2.DESCRIPTOR) in files
    # the reader hides the descriptor entries by default and decodes from them
    reader = LogReader(bytes(out))
    decoder = EntryDecoder(reader.descriptors)
    assert [Sample.FromString(decoder.decode(e).messages[0].SerializeToString()).a for e in reader] == [5, 6]


def test_our_debug_text_of_a_real_goby_logger_file_is_goby_log_tools() -> None:
    reader = LogReader(DATA / "real_goby_logger_3.1.5.goby")
    decoder = EntryDecoder(reader.descriptors)
    lines = [debug_text_line(e, decoder.decode(e)) for e in reader]
    assert reader.version == 3 and reader.skipped == []
    assert lines == (DATA / "real_goby_logger_3.1.5.txt").read_text().splitlines()
    # the LoggerConfig came from the descriptors the log carries (this test does not import its module)
    assert "log_dir: \"/tmp/glx\"" in next(line for line in lines if "LoggerConfig" in line)


def test_round_trip_names_payloads_and_values() -> None:
    reader = LogReader(sample_log())
    decoder = EntryDecoder(reader.descriptors)
    entries = list(reader)
    assert [(e.scheme, e.group, e.type_name, e.timestamp_micro) for e in entries] == [
        (0, "text", "CSTR", T0), (1, "nav", "goby.test.zeromq.protobuf.Sample", T0 + 1), (0, "text", "CSTR", T0 + 2),
        (7, "json", "nlohmann::json", T0 + 3), (0, "text", "CSTR", T0 + 4)]
    assert entries[2].data == b"two\0"
    assert decoder.decode(entries[3]).json == {"x": 1, "s": "y"}
    objs = json_objects(entries[1], decoder.decode(entries[1]))
    assert objs == [{"a": 1, "_scheme_": 1, "_utime_": T0 + 1, "_strtime_": "2026-Nov-28 09:55:07.386270",
                     "_group_": "nav", "_type_": "goby.test.zeromq.protobuf.Sample"}]


def test_unknown_type_is_kept_as_bytes_with_a_named_warning(caplog: pytest.LogCaptureFixture) -> None:
    out = bytearray()
    LogWriter(out.extend, ticking_clock()).write(b"\x08\x01", Scheme.PROTOBUF, "no.such.Type", "g")
    reader = LogReader(bytes(out))
    decoder = EntryDecoder(reader.descriptors)
    [entry] = list(reader)
    value = decoder.decode(entry)
    assert value.error is not None and "no.such.Type" in value.error
    assert "Unable to parse message of 2 bytes" in debug_text_line(entry, value)
    assert any("no.such.Type" in r.getMessage() for r in caplog.records)


# ----------------------------------------------------------------------------------------------- damaged logs
def offsets(data: bytes) -> list[int]:
    return [e.offset for e in LogReader(data)]


def test_every_truncation_reads_a_prefix_and_reports_the_tail() -> None:
    whole = sample_log()
    full = [(e.offset, e.data) for e in LogReader(whole)]
    for cut in range(4, len(whole)):
        reader = LogReader(whole[:cut])
        got = [(e.offset, e.data) for e in reader]
        assert got == full[:len(got)]
        complete = sum(1 for off, data in full if off + 22 + len(data) + 4 <= cut)
        assert len(got) == complete, cut
        if reader.skipped:
            [span] = reader.skipped
            assert span.offset + span.length == cut and "truncated" in span.reason


def test_flipped_bit_skips_that_entry_only() -> None:
    whole = bytearray(sample_log())
    entries = list(LogReader(bytes(whole)))
    victim = entries[2]  # "two"
    whole[victim.offset + 22] ^= 0x04
    reader = LogReader(bytes(whole))
    got = list(reader)
    assert [e.data for e in got] == [e.data for e in entries if e is not victim]
    [span] = reader.skipped
    assert span.offset == victim.offset and span.length == 22 + 4 + 4 and "CRC mismatch" in span.reason


def test_garbage_between_entries_is_reported_at_its_offset() -> None:
    whole = sample_log()
    entries = list(LogReader(whole))
    at = entries[3].offset
    damaged = whole[:at] + b"GBY\x00junk" * 3 + whole[at:]
    reader = LogReader(damaged)
    assert [e.data for e in reader] == [e.data for e in entries]
    [span] = reader.skipped
    assert (span.offset, span.length) == (at, 24)


def test_corrupt_size_does_not_allocate_and_resynchronises() -> None:
    whole = bytearray(sample_log())
    entries = list(LogReader(bytes(whole)))
    whole[entries[1].offset + 4:entries[1].offset + 8] = b"\xff\xff\xff\xf0"
    reader = LogReader(bytes(whole))
    assert [e.data for e in reader] == [e.data for e in entries if e is not entries[1]]
    assert reader.skipped[0].offset == entries[1].offset


def test_unknown_scheme_is_skipped_and_reported() -> None:
    whole = sample_log()
    entries = list(LogReader(whole))
    at = entries[2].offset
    foreign = record(0x0099, 1, 1, T0, b"??")
    reader = LogReader(whole[:at] + foreign + whole[at:])
    assert [e.data for e in reader] == [e.data for e in entries]
    [span] = reader.skipped
    assert (span.offset, span.length) == (at, len(foreign)) and "unknown scheme 153" in span.reason


def test_newer_version_is_refused_by_name() -> None:
    with pytest.raises(NewerVersionError, match="version 4 is newer than this reader's .3."):
        LogReader(struct.pack(">I", 4) + sample_log()[4:])
    with pytest.raises(LogFormatError, match="shorter than the version header"):
        LogReader(b"\x00\x00")


def test_bson_rejects_malformed_documents_without_raising_anything_else() -> None:
    good = bson.encode({"a": [1, 2, {"b": "c"}], "d": 2.5, "e": None, "f": True, "g": 1 << 40})
    assert bson.decode(good)["a"][2] == {"b": "c"}
    for cut in range(len(good)):
        with pytest.raises(bson.BsonError):
            bson.decode(good[:cut])
    with pytest.raises(bson.BsonError):
        bson.decode(b"\xff\xff\xff\x7f" + good[4:])  # a length of 2 GiB: refused, not allocated
