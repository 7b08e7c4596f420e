"""usv-command -> usv-manager -> CommandTranslation -> MOOS, with real processes and real bytes."""

from __future__ import annotations

import time

from translator_procs import run_cli

from gateway.goby.portal.testing import PortalClient
from gateway.moos.message import MoosMessage
from gateway.moos.testing import connected_comms
from translators.usv import groups as usv_groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand

COMMAND_VARS = ["POLYGON_UPDATES", "DEPLOY_STATE"]
MAIL_TIMEOUT_S = 30.0


def mail_until(watcher, predicate, timeout_s: float = MAIL_TIMEOUT_S, since: float | None = None) -> list[MoosMessage]:  # noqa: ANN001,E501
    """Fetch until ``predicate(mail)`` holds or the timeout passes, keeping messages stamped at/after ``since``.

    Registering makes the DB send each variable's current value (posted by an earlier test); those carry older
    MOOS times, so ``since`` (taken just before the action under test) leaves them out.
    """
    got: list[MoosMessage] = []
    deadline = time.monotonic() + timeout_s
    while not predicate(got) and time.monotonic() < deadline:
        got.extend(m for m in watcher.fetch() if since is None or m.time() >= since)
        time.sleep(0.01)
    return got


def settle(watcher) -> float:  # noqa: ANN001
    """Drain the registration echoes for a moment; return the time from which new mail counts."""
    mail_until(watcher, lambda got: False, 0.5)
    return time.time()


def pairs(mail: list[MoosMessage]) -> list[tuple[str, str]]:
    return [(m.key(), m.string()) for m in mail]


def test_polygon_command_posts_polygon_updates_then_deploy_state(stack):
    with connected_comms(stack.moos_port, "watch_polygon", register=COMMAND_VARS) as watcher:
        since = settle(watcher)
        result = run_cli(["polygon", "--sides", "6", "--radius", "300"], stack.env(), stack.workdir)
        assert result.returncode == 0, f"{result.stdout}\n{result.stderr}\n{stack.logs()}"
        assert "sent: " in result.stdout and "desired_state: POLYGON" in result.stdout
        assert "received by usv-manager" in result.stdout
        assert ("acknowledged by goby::moos::Translator::" in result.stdout
                and "POLYGON_UPDATES=polygon=radial::x=0,y=0,radius=300,pts=6, DEPLOY_STATE=POLYGON" in result.stdout)
        mail = mail_until(watcher, lambda got: ("DEPLOY_STATE", "POLYGON") in pairs(got), since=since)
    assert pairs(mail) == [
        ("POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=300,pts=6"),
        ("DEPLOY_STATE", "POLYGON"),
    ], stack.logs()
    assert mail[0].is_string() and mail[1].is_string()


def test_waypoints_command_posts_only_deploy_state(stack):
    with connected_comms(stack.moos_port, "watch_waypoints", register=COMMAND_VARS) as watcher:
        since = settle(watcher)
        result = run_cli(["waypoints", "--timeout", "30"], stack.env(), stack.workdir)
        assert result.returncode == 0, f"{result.stdout}\n{result.stderr}"
        assert "posted DEPLOY_STATE=WAYPOINTS" in result.stdout
        mail = mail_until(watcher, lambda got: ("DEPLOY_STATE", "WAYPOINTS") in pairs(got), since=since)
    assert pairs(mail) == [("DEPLOY_STATE", "WAYPOINTS")]


def test_radius_is_rounded_to_dccl_precision(stack):
    with connected_comms(stack.moos_port, "watch_rounding", register=["POLYGON_UPDATES"]) as watcher:
        since = settle(watcher)
        result = run_cli(["polygon", "--sides", "4", "--radius", "1234"], stack.env(), stack.workdir)
        assert result.returncode == 0, result.stdout + result.stderr
        mail = mail_until(watcher, lambda got: len(got) >= 1, since=since)
    assert pairs(mail) == [("POLYGON_UPDATES", "polygon=radial::x=0,y=0,radius=1230,pts=4")]


def test_out_of_range_command_is_refused_before_anything_is_sent(stack):
    with connected_comms(stack.moos_port, "watch_refused", register=COMMAND_VARS) as watcher:
        since = settle(watcher)
        refused = run_cli(["polygon", "--sides", "11", "--radius", "300"], stack.env(), stack.workdir)
        assert refused.returncode == 1
        assert "polygon_sides=11 is outside its DCCL bounds [3, 10]" in refused.stderr
        assert "sent: " not in refused.stdout
        radius = run_cli(["polygon", "--sides", "5", "--radius", "2500"], stack.env(), stack.workdir)
        assert radius.returncode == 1 and "polygon_radius=2500" in radius.stderr
        # A later good command is the first thing MOOS sees: nothing of the refused ones leaked through.
        ok = run_cli(["waypoints"], stack.env(), stack.workdir)
        assert ok.returncode == 0, ok.stdout + ok.stderr
        mail = mail_until(watcher, lambda got: ("DEPLOY_STATE", "WAYPOINTS") in pairs(got), since=since)
    assert pairs(mail) == [("DEPLOY_STATE", "WAYPOINTS")]


def test_manager_and_translator_refuse_bad_commands_from_other_publishers(stack):
    """Commands that bypass usv-command: usv-manager checks the shore leg, CommandTranslation the vehicle leg."""
    with connected_comms(stack.moos_port, "watch_bypass", register=COMMAND_VARS) as watcher, \
            PortalClient(stack.broker.interprocess_config(), name="bypass") as client:
        since = settle(watcher)
        acks = client.collect(usv_groups.usv_command_ack, USVCommandAck)
        assert client.wait_subscribed()
        too_big = USVCommand(time=1.5, desired_state=USVCommand.POLYGON, polygon_sides=6, polygon_radius=5000)
        client.publish(usv_groups.shore_usv_command, too_big)
        no_shape = USVCommand(time=2.5, desired_state=USVCommand.POLYGON)
        client.publish(usv_groups.usv_command, no_shape)
        good = USVCommand(time=3.5, desired_state=USVCommand.WAYPOINTS)
        client.publish(usv_groups.usv_command, good)
        assert client.poll_until(lambda: {a.command_time for a in acks} >= {1.5, 2.5, 3.5}, 30), stack.logs()
        mail = mail_until(watcher, lambda got: ("DEPLOY_STATE", "WAYPOINTS") in pairs(got), since=since)
    by_time = {a.command_time: a for a in acks}
    assert by_time[1.5].stage == USVCommandAck.REFUSED and by_time[1.5].responder == "usv-manager"
    assert "polygon_radius=5000 is outside its DCCL bounds [100, 2000]" in by_time[1.5].error
    assert by_time[2.5].stage == USVCommandAck.REFUSED
    assert by_time[2.5].responder.startswith("goby::moos::Translator::")
    assert "POLYGON command without polygon_sides and polygon_radius" in by_time[2.5].error
    assert by_time[3.5].stage == USVCommandAck.POSTED_TO_MOOS
    assert list(by_time[3.5].moos_post) == ["DEPLOY_STATE=WAYPOINTS"]
    assert pairs(mail) == [("DEPLOY_STATE", "WAYPOINTS")]  # the refused ones never reached MOOS
