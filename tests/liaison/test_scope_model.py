"""The scope's rows: coalescing, counts, rates, history, decoding, and its bounds."""

from __future__ import annotations

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from gateway.goby.dccl import Codec
from gateway.goby.portal.marshalling import Scheme
from launch.liaison.decode import decode_payload
from launch.liaison.scope_model import ScopeModel
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

NODE = NodeStatus.DESCRIPTOR.full_name


def node(x: float) -> bytes:
    status = NodeStatus(time=1, name="usv")
    status.global_fix.lat, status.global_fix.lon = 1, 2
    status.pose.heading = x
    status.speed.over_ground = 1
    return status.SerializeToString()


def test_a_thousand_publications_make_one_row_decoded_once_per_tick():
    scope = ScopeModel(max_history=10)
    for i in range(1000):
        scope.ingest("nav", Scheme.PROTOBUF, NODE, node(i), when=100.0 + i)
    first = scope.tick(0.0)
    assert len(first) == 1
    row = first[0]
    assert row["count"] == 1000 and row["time"] == 1099.0 and "heading: 999" in row["value"] and row["ok"]
    history = scope.history(row["id"])
    assert len(history) == 10 and "heading: 999" in history[0]["value"]  # newest first, bounded
    assert scope.history(row["id"] + 1) is None


def test_rate_follows_the_publication_rate():
    scope = ScopeModel()
    t = 0.0
    scope.tick(t)
    for _ in range(30):  # 50 publications per 0.2 s = 250 Hz
        for _ in range(50):
            scope.ingest("fast", Scheme.CSTR, "CSTR", b"x\0", 0)
        t += 0.2
        scope.tick(t)
    (row,) = scope.views()
    assert 230 < row["rate"] < 260


def test_one_row_per_group_type_and_scheme():
    scope = ScopeModel()
    scope.ingest("g", Scheme.PROTOBUF, NODE, node(1), 0)
    scope.ingest("g", Scheme.DCCL, NODE, b"\x01\x02", 0)
    scope.ingest("g", Scheme.CSTR, "CSTR", b"hello\0", 0)
    scope.ingest("g", Scheme.JSON, "j", b"{}", 0)
    rows = {(r["scheme"], r["value"]) for r in scope.tick(0)}
    assert ("CSTR", "hello") in rows
    assert ("DCCL", f"2 bytes: 01 02 (does not parse as {NODE}: {NODE} has no DCCL options)") in rows
    assert ("JSON", "2 bytes: 7b 7d (no decoder for this scheme)") in rows
    assert len(rows) == 4


def test_dccl_payloads_of_a_loaded_type_are_decoded_with_the_dccl_codec():
    """The intervehicle layer's echoes on interprocess (scheme DCCL) show as text, as the PROTOBUF ones do."""
    command = USVCommand(time=1700000000.5, desired_state=USVCommand.POLYGON, polygon_sides=8, polygon_radius=400)
    codec = Codec()
    codec.load(USVCommand)
    data = codec.encode(command)
    assert len(data) == 5  # the course's 5-byte command, not protobuf bytes
    scope = ScopeModel()
    scope.ingest("goby3_course::usv_command;0", Scheme.DCCL, "goby3_course.dccl.USVCommand", data, 0)
    (row,) = scope.tick(0)
    assert row["ok"] and row["scheme"] == "DCCL"
    assert "desired_state: POLYGON" in row["value"] and "polygon_sides: 8 polygon_radius: 400" in row["value"]
    truncated = decode_payload(data[:3], Scheme.DCCL, "goby3_course.dccl.USVCommand", dccl=Codec())
    assert not truncated.ok and truncated.short.startswith("3 bytes: ") and "does not parse" in truncated.short
    assert decode_payload(data, Scheme.DCCL, "goby3_course.dccl.USVCommand").short.endswith(
        "(no decoder for this scheme)")  # no codec given


def test_rows_are_bounded():
    scope = ScopeModel(max_rows=3)
    for i in range(5):
        scope.ingest(f"g{i}", Scheme.CSTR, "CSTR", b"x\0", 0)
    assert scope.row_count() == 3 and scope.refused_rows == 2


def test_unknown_unparsable_and_oversized_payloads_are_shown_as_hex():
    assert decode_payload(b"\x08\x01", Scheme.PROTOBUF, "no.such.Type").short == "2 bytes: 08 01 (type not loaded)"
    bad = decode_payload(b"\xff\xff", Scheme.PROTOBUF, NODE)
    assert not bad.ok and "does not parse" in bad.short
    big = decode_payload(b"\0" * 3000, Scheme.PROTOBUF, NODE, max_size=2048)
    assert big.short.startswith("3000 bytes: 00 00") and "max_message_size_bytes 2048" in big.short
