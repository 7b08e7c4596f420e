"""LogFollower: a log read while it is written, in pieces of any size, gives LogReader's entries; damage is skipped."""

from __future__ import annotations

from pathlib import Path

from gateway.goby.log import LogReader, LogWriter
from gateway.goby.log.follow import LogFollower
from gateway.goby.portal import Scheme
from tests.goby_log.test_format import T0, ticking_clock
from tests.protobuf.sample_messages_pb2 import Sample


def _log_bytes() -> bytes:
    out = bytearray()
    writer = LogWriter(out.extend, ticking_clock())  # with descriptor entries
    for i in range(40):
        writer.write(Sample(a=i).SerializeToString(), Scheme.PROTOBUF, "goby.test.zeromq.protobuf.Sample",
                     f"nav{i % 3}", T0 + i)
        writer.write(f"text {i}\0".encode(), Scheme.CSTR, "CSTR", "text", T0 + i)
    return bytes(out)


def _key(entries: list) -> list[tuple]:
    return [(e.scheme, e.group, e.type_name, e.timestamp_micro, e.data, e.offset) for e in entries]


def test_follower_reads_a_growing_file_in_odd_pieces(tmp_path: Path) -> None:
    data = _log_bytes()
    path = tmp_path / "growing.goby"
    follower = LogFollower(path)
    assert follower.poll() == []  # no file yet
    got = []
    with open(path, "wb") as out:
        for start in range(0, len(data), 37):  # pieces that cut headers, data and CRCs
            out.write(data[start:start + 37])
            out.flush()
            got += follower.poll()
    follower.close()
    expected = list(LogReader(data))
    assert len(expected) == 80
    assert _key(got) == _key(expected)
    assert follower.skipped == []
    assert follower.descriptors.message_class("goby.test.zeromq.protobuf.Sample") is not None


def test_follower_skips_damage_and_goes_on(tmp_path: Path) -> None:
    data = bytearray(_log_bytes())
    entries = list(LogReader(bytes(data)))
    victim = entries[10]
    data[victim.offset + 25] ^= 0x01  # a flipped bit in the entry's CRC (22 header bytes, 2 of data)
    garbage_at = entries[20].offset
    data[garbage_at:garbage_at] = b"garbage!"
    path = tmp_path / "damaged.goby"
    path.write_bytes(bytes(data))
    with LogFollower(path) as follower:
        got = follower.poll()
    reasons = [s.reason for s in follower.skipped]
    assert reasons[0].startswith("CRC mismatch") and reasons[1:] == ["bytes between entries that are not an entry"]
    whole = LogReader(bytes(data))
    list(whole)
    assert follower.skipped == whole.skipped  # one parser: the same spans, offsets and reasons as a finished file's
    assert follower.skipped[1].offset == garbage_at and follower.skipped[1].length == 8
    assert len(got) == len(entries) - 1
    assert victim.data not in [e.data for e in got if e.timestamp_micro == victim.timestamp_micro
                               and e.group == victim.group]
