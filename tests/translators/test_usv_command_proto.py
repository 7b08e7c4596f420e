"""The course's USVCommand compiles with DCCL's options, and the USV command path enforces the DCCL codec's bounds."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gateway.goby.dccl import Codec
from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from translators.usv.validation import DcclBoundsError, check_dccl_bounds

REPO = Path(__file__).resolve().parents[2]
COURSE_PROTO = REPO / "translators" / "usv" / "protobuf" / "command_dccl.proto"


def polygon(sides: int, radius: int) -> USVCommand:
    return USVCommand(time=1700000000.5, desired_state=USVCommand.POLYGON, polygon_sides=sides, polygon_radius=radius)


def test_dccl_extensions_use_dccls_numbers_and_names():
    assert dccl_options.field.number == 1012
    assert dccl_options.msg.number == 1012
    assert dccl_options.field.full_name == "dccl.field"
    assert dccl_options.msg.full_name == "dccl.msg"
    assert dccl_options.DCCLFieldOptions.DESCRIPTOR.fields_by_name["precision"].number == 4
    assert dccl_options.DCCLFieldOptions.DESCRIPTOR.fields_by_name["min"].number == 5
    assert dccl_options.DCCLFieldOptions.DESCRIPTOR.fields_by_name["units"].number == 30
    assert dccl_options.DCCLMessageOptions.DESCRIPTOR.fields_by_name["unit_system"].number == 30


def test_usv_command_message_options_and_fields():
    options = USVCommand.DESCRIPTOR.GetOptions().Extensions[dccl_options.msg]
    assert (options.id, options.max_bytes, options.codec_version, options.unit_system) == (126, 32, 3, "si")
    assert USVCommand.DESCRIPTOR.full_name == "goby3_course.dccl.USVCommand"
    numbers = {f.name: f.number for f in USVCommand.DESCRIPTOR.fields}
    assert numbers == {"time": 1, "desired_state": 2, "polygon_sides": 3, "polygon_radius": 4}
    assert USVCommand.WAYPOINTS == 1 and USVCommand.POLYGON == 2
    time_options = USVCommand.DESCRIPTOR.fields_by_name["time"].GetOptions().Extensions[dccl_options.field]
    assert time_options.codec == "dccl.time2" and time_options.units.derived_dimensions == "time"


def test_the_codec_reads_the_bounds_from_the_descriptor():
    codec = Codec()
    codec.load(USVCommand)
    bounds = {b.name: b for b in codec.bounds(USVCommand)}
    assert (bounds["polygon_sides"].min, bounds["polygon_sides"].max, bounds["polygon_sides"].resolution) == (3, 10, 1)
    assert (bounds["polygon_radius"].min, bounds["polygon_radius"].max, bounds["polygon_radius"].resolution) == (
        100, 2000, 10)
    assert bounds["time"].time and bounds["time"].min is None


@pytest.mark.parametrize(("sides", "radius", "sent"), [(3, 100, 100), (10, 2000, 2000), (6, 304, 300), (6, 305, 310), (6, 95, 100)])
def test_in_bounds_values_pass_rounded_to_the_precision(sides, radius, sent):
    notices: list[str] = []
    checked = check_dccl_bounds(polygon(sides, radius), notices)
    assert (checked.polygon_sides, checked.polygon_radius) == (sides, sent)
    assert checked.time == 1700000000.5  # the stamp identifies acknowledgements: kept as sent
    if sent != radius:
        assert notices == [f"USVCommand.polygon_radius={radius} is sent as {sent} (DCCL: [100, 2000], in steps of 10)"]
    else:
        assert notices == []


@pytest.mark.parametrize(
    ("sides", "radius", "message"),
    [
        (2, 300, r"polygon_sides=2 is outside its DCCL bounds \[3, 10\]"),
        (11, 300, r"polygon_sides=11 is outside"),
        (6, 94, r"polygon_radius=94 is outside its DCCL bounds \[100, 2000\], in steps of 10"),
        (6, 2005, r"polygon_radius=2005 is outside"),
        (6, -300, r"polygon_radius=-300"),
    ],
)
def test_out_of_bounds_values_are_refused_with_the_field_and_bounds(sides, radius, message):
    with pytest.raises(DcclBoundsError, match=message):
        check_dccl_bounds(polygon(sides, radius))


def test_missing_required_fields_are_refused():
    with pytest.raises(DcclBoundsError, match="desired_state"):
        check_dccl_bounds(USVCommand(time=1.0))


def test_waypoints_needs_no_polygon_fields():
    checked = check_dccl_bounds(USVCommand(time=1.0, desired_state=USVCommand.WAYPOINTS))
    assert not checked.HasField("polygon_sides")


# The course's file as the day-3 lecture shows it (what a user brings), byte for byte apart from whitespace.
COURSE_TEXT = """syntax = "proto2";
import "dccl/option_extensions.proto";
package goby3_course.dccl;
message USVCommand {
    option (.dccl.msg) = { codec_version: 3 id: 126 max_bytes: 32 unit_system: "si" };
    required double time = 1 [(.dccl.field) = { codec: "dccl.time2", units {derived_dimensions: "time"} }];
    enum AutonomyState { WAYPOINTS = 1; POLYGON = 2; }
    required AutonomyState desired_state = 2;
    optional int32 polygon_sides = 3 [(.dccl.field) = {min: 3 max: 10}];
    optional int32 polygon_radius = 4 [(.dccl.field) = {min: 100 max: 2000 precision: -1}];
}
"""


@pytest.mark.parametrize("source", ["lecture", "ours"])
def test_the_course_proto_compiles_unchanged_with_protoc(tmp_path, source):
    """protoc accepts the course's file, importing "dccl/option_extensions.proto" from our include directory."""
    grpc_tools = pytest.importorskip("grpc_tools")
    course_copy = tmp_path / "command_dccl.proto"
    if source == "lecture":
        course_copy.write_text(COURSE_TEXT)
    else:
        shutil.copy(COURSE_PROTO, course_copy)
    result = subprocess.run(
        [
            sys.executable, "-m", "grpc_tools.protoc",
            f"-I{REPO / 'gateway' / 'goby' / 'protobuf' / 'include'}", f"-I{tmp_path}",
            f"-I{Path(grpc_tools.__file__).parent / '_proto'}",
            f"--descriptor_set_out={tmp_path / 'set.pb'}", str(course_copy),
        ],
        capture_output=True, text=True, timeout=60,
    )
    assert result.returncode == 0, result.stderr
    from google.protobuf import descriptor_pb2

    files = descriptor_pb2.FileDescriptorSet.FromString((tmp_path / "set.pb").read_bytes())
    compiled = files.file[0].message_type[0]
    for field in compiled.field:
        field.ClearField("json_name")  # protoc adds it; CopyToProto does not
    ours = descriptor_pb2.DescriptorProto()
    USVCommand.DESCRIPTOR.CopyToProto(ours)
    assert compiled.SerializeToString(deterministic=True) == ours.SerializeToString(deterministic=True)


@settings(max_examples=200, deadline=None)
@given(sides=st.integers(-50, 50), radius=st.integers(-5000, 5000))
def test_a_checked_command_is_always_inside_the_bounds_or_refused(sides, radius):
    try:
        checked = check_dccl_bounds(polygon(sides, radius))
    except DcclBoundsError as error:
        assert "outside its DCCL bounds" in str(error)
        assert not (3 <= sides <= 10) or not (95 <= radius < 2005)
    else:
        assert 3 <= checked.polygon_sides <= 10 and checked.polygon_sides == sides
        assert 100 <= checked.polygon_radius <= 2000 and checked.polygon_radius % 10 == 0
        assert abs(checked.polygon_radius - radius) <= 5
