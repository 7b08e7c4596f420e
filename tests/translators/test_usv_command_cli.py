"""usv-command on its own: argument handling, the command it builds, and the exit code when nobody answers."""

from __future__ import annotations

import sys

import pytest
from translator_procs import run_cli, start_child, wait_showing_logs

from gateway.goby.portal.testing import PortalClient, broker_process
from translators.apps.usv_command import (
    EXIT_UNACKNOWLEDGED,
    build_command,
    build_parser,
    describe_ack,
)
from translators.usv import groups as usv_groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand


def parse(argv: list[str]):  # noqa: ANN201
    return build_parser().parse_known_args(argv)


def test_polygon_arguments_build_the_course_message():
    args, rest = parse(["polygon", "--sides", "6", "--radius", "300", "--timeout", "4", "--interprocess", "x"])
    command = build_command(args, 1234.5)
    assert command == USVCommand(time=1234.5, desired_state=USVCommand.POLYGON, polygon_sides=6, polygon_radius=300)
    assert args.timeout == 4.0
    assert rest == ["--interprocess", "x"]  # left for the Goby configuration parser


@pytest.mark.parametrize("timeout", ["-1", "0", "nan", "inf", "soon"])
def test_timeout_must_be_a_finite_positive_number(timeout, capsys):
    with pytest.raises(SystemExit) as exit_:
        parse(["waypoints", "--timeout", timeout])
    assert exit_.value.code == 2 and "--timeout" in capsys.readouterr().err


def test_waypoints_needs_no_shape():
    args, rest = parse(["waypoints"])
    assert build_command(args, 1.0) == USVCommand(time=1.0, desired_state=USVCommand.WAYPOINTS)
    assert rest == [] and args.timeout is None


def test_polygon_without_its_shape_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as exit_info:
        parse(["polygon", "--sides", "6"])
    assert exit_info.value.code == 2
    assert "--radius" in capsys.readouterr().err


def test_describe_ack():
    posted = USVCommandAck(stage=USVCommandAck.POSTED_TO_MOOS, responder="t", moos_post=["A=1", "B=2"])
    assert describe_ack(posted) == "acknowledged by t: posted A=1, B=2"
    refused = USVCommandAck(stage=USVCommandAck.REFUSED, responder="usv-manager", error="too big")
    assert describe_ack(refused) == "refused by usv-manager: too big"


def test_without_a_translator_the_command_is_not_acknowledged(tmp_path):
    """usv-manager answers but no gateway does: the CLI reports it and exits 3 after its timeout."""
    with broker_process(tmp_path, platform="shore") as broker:
        manager = start_child("usv_manager", [sys.executable, "-m", "translators.apps.usv_manager", "-v"], tmp_path,
                               broker.env())
        try:
            with PortalClient(broker.interprocess_config(), name="probe") as client:
                acks = client.collect(usv_groups.usv_command_ack, USVCommandAck)
                assert client.wait_subscribed()
                wait_showing_logs(lambda: client.publish(usv_groups.shore_usv_command, USVCommand(
                    time=7.0, desired_state=USVCommand.WAYPOINTS)) or client.poll_until(lambda: bool(acks), 0.5),
                    60, "usv-manager to answer", manager)
            result = run_cli(["waypoints", "--timeout", "3"], broker.env(), tmp_path)
        finally:
            manager.stop()
    assert result.returncode == EXIT_UNACKNOWLEDGED, result.stdout + result.stderr
    assert "received by usv-manager" in result.stdout
    assert "NOT acknowledged within 3 s" in result.stdout


def test_bad_goby_option_is_a_configuration_error(tmp_path):
    result = run_cli(["waypoints", "--interprocess", "no_such_field: 1"], {}, tmp_path)
    assert result.returncode == 2
    assert "no_such_field" in result.stderr


def test_example_config_needs_no_command(capsys):
    from translators.apps.usv_command import main

    assert main(["--example_config"]) == 0
    out = capsys.readouterr().out
    assert "ack_timeout: 10" in out and "interprocess {" in out


def test_a_radius_off_the_dccl_step_is_sent_rounded_with_a_notice(tmp_path):
    result = run_cli(["polygon", "--sides", "6", "--radius", "304", "--interprocess", "no_such_field: 1"], {},
                     tmp_path)  # stops at the bad option, after the command was checked
    assert "note: USVCommand.polygon_radius=304 is sent as 300 (DCCL: [100, 2000], in steps of 10)" in result.stderr
