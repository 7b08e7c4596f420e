"""dccl-py: analyze, encode and decode on the command line, as the C++ ``dccl`` tool does."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from gateway.apps.dccl_py import main

REPO = Path(__file__).resolve().parents[2]
COMMANDS = ["-l", "translators.usv.protobuf.command_dccl_pb2"]
USV = ["-m", "goby3_course.dccl.USVCommand"]


def run(capsys, argv: list[str], stdin: str = "") -> tuple[int, str, str]:
    import sys

    old = sys.stdin
    sys.stdin = io.TextIOWrapper(io.BytesIO(stdin.encode()))
    try:
        code = main(argv)
    finally:
        sys.stdin = old
    out = capsys.readouterr()
    return code, out.out, out.err


def test_analyze_prints_dccls_size_report(capsys):
    code, out, _ = run(capsys, ["-a", *COMMANDS, *USV])
    assert code == 0
    assert out.splitlines()[:2] == ["============= 126: goby3_course.dccl.USVCommand =============",
                                    "Actual maximum size of message: 5 bytes / 40 bits"]
    assert "        4. polygon_radius......................8 {dccl.default3}" in out


def test_encode_from_arguments_and_stdin_then_decode(capsys):
    code, out, _ = run(capsys, ["-e", *COMMANDS, *USV, "time: 1700000000 desired_state: WAYPOINTS"])
    assert (code, out) == (0, "fc80380100\n")
    code, out, _ = run(capsys, ["-e", *COMMANDS, *USV],
                       "|goby3_course.dccl.AUVCommand| time: 1700000000 desired_state: TRAIL\n\n")
    assert (code, out) == (0, "fe803801\n")
    code, out, _ = run(capsys, ["-d", *COMMANDS, "--now", "1700000000", "fc80380100fe803801"])
    assert code == 0
    assert out.splitlines() == ["|goby3_course.dccl.USVCommand| time: 1700000000.0 desired_state: WAYPOINTS",
                                "|goby3_course.dccl.AUVCommand| time: 1700000000.0 desired_state: TRAIL"]


@pytest.mark.parametrize(("fmt", "encoded"), [("textformat", '"\\374\\2008\\001\\000"'), ("base64", "/IA4AQA=")])
def test_other_formats(capsys, fmt, encoded):
    code, out, _ = run(capsys, ["-e", *COMMANDS, *USV, "--format", fmt, "time: 1700000000 desired_state: 1"])
    assert (code, out.strip()) == (0, encoded)
    code, out, _ = run(capsys, ["-d", *COMMANDS, "-o", "--format", fmt, "--now", "1700000000", encoded])
    assert (code, out.strip()) == (0, "time: 1700000000.0 desired_state: WAYPOINTS")


def test_errors_are_one_line_and_exit_1(capsys):
    code, _, err = run(capsys, ["-d", *COMMANDS, "fc8038"])
    assert code == 1 and "goby3_course.dccl.USVCommand needs 5 bytes but only 3 are there" in err
    code, _, err = run(capsys, ["-e", *COMMANDS, *USV, "--strict", "time: 1 desired_state: POLYGON polygon_sides: 12"])
    assert code == 1 and "USVCommand.polygon_sides=12 is outside its DCCL bounds [3, 10]" in err
    code, _, err = run(capsys, ["-a", *COMMANDS, "-m", "no.Such"])
    assert code == 1 and "No descriptor with name no.Such found" in err
    code, _, err = run(capsys, ["-a", "-l", "tests.protobuf.sample_messages_pb2", "-m", "goby.test.zeromq.protobuf.Sample"])
    assert code == 1 and "Not a valid DCCL message: goby.test.zeromq.protobuf.Sample" in err


def test_source_shows_the_generated_functions(capsys):
    code, out, _ = run(capsys, ["--source", *COMMANDS, *USV])
    assert code == 0 and "def encode(m):" in out and "def decode(data, start, now):" in out


def test_proto_files_are_compiled_with_dccls_options_on_the_path(capsys):
    pytest.importorskip("grpc_tools")
    proto = REPO / "translators" / "trail" / "protobuf" / "nav_dccl.proto"
    code, out, err = run(capsys, ["-e", "-f", str(proto)],
                         "vehicle: 1 time: 1700000000 x: 0 y: 0 z: 0 speed_over_ground: 0 heading: 0\n")
    assert (code, out) == (0, "f800409ca086811a0677010000\n")  # the C++ codec's bytes
    assert "Encoding assuming message: goby3_course.dccl.NavigationReport" in err
