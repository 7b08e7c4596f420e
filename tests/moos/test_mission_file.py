"""MissionFile reads .moos files as libMOOS's CMOOSFileReader does (spec §11)."""

from __future__ import annotations

from pathlib import Path

import pytest

from gateway.moos.errors import MissionFileError
from gateway.moos.mission_file import MissionFile

MISSION = """\
// a comment line
ServerHost = localhost
ServerPort   = 9001   // trailing comment
Community    = alpha
MOOSTimeWarp = 5
define: SPEED = 1.5
LatOrigin  = 41.592344
LongOrigin = -70.711260
MissionName = my  long mission

ProcessConfig = pHelmIvP
{
  AppTick   = 4
  behaviors = usv.bhv
  domain    = course:0:359:360
  domain    = speed:0:4:41
  ok_skew   = any
  empty     =
  bracket   = [
  speed     = ${SPEED}
  url       = "http://example.org//x"  // the quoted part keeps its slashes
}

ProcessConfig = ANTLER
{
  MSBetweenLaunches = 200
  Run = MOOSDB @ NewConsole = false
  Run = pHelmIvP @ NewConsole = false ~ pHelm2
}
"""


@pytest.fixture
def mission(tmp_path: Path) -> MissionFile:
    path = tmp_path / "m.moos"
    path.write_text(MISSION)
    return MissionFile(path)


def test_globals_are_case_insensitive_and_lose_whitespace(mission: MissionFile) -> None:
    assert mission.global_value("serverport") == "9001"
    assert mission.global_value("SERVERHOST") == "localhost"
    assert mission.global_value("MissionName") == "mylongmission"
    assert mission.global_value("NoSuchThing") is None


def test_typed_properties(mission: MissionFile) -> None:
    assert mission.server_host == "localhost"
    assert mission.server_port == 9001
    assert mission.community == "alpha"
    assert mission.time_warp == 5.0
    assert mission.lat_origin == pytest.approx(41.592344)
    assert mission.long_origin == pytest.approx(-70.711260)


def test_defaults_when_absent() -> None:
    empty = MissionFile.from_text("// nothing\n")
    assert (empty.server_host, empty.server_port, empty.community, empty.time_warp) == ("localhost", 9000, "#1", 1.0)
    assert empty.lat_origin is None and empty.long_origin is None


def test_first_match_anywhere_wins_even_inside_blocks() -> None:
    text = "ProcessConfig = a\n{\n  Community = inside\n}\nCommunity = outside\n"
    assert MissionFile.from_text(text).community == "inside"


def test_process_config_in_file_order_with_spaces_kept(mission: MissionFile) -> None:
    cfg = mission.process_config("phelmivp")
    assert cfg == [
        ("AppTick", "4"),
        ("behaviors", "usv.bhv"),
        ("domain", "course:0:359:360"),
        ("domain", "speed:0:4:41"),
        ("ok_skew", "any"),
        ("bracket", "["),
        ("speed", "1.5"),
        ("url", "http://example.org//x"),
    ]
    antler = mission.process_config("ANTLER")
    assert antler[2] == ("Run", "pHelmIvP @ NewConsole = false ~ pHelm2")
    assert mission.process_param("pHelmIvP", "DOMAIN") == "course:0:359:360"
    assert mission.process_config("absent") == []
    assert mission.process_names() == ["pHelmIvP", "ANTLER"]


def test_environment_variables_expand(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MY_PORT", "9123")
    assert MissionFile.from_text("ServerPort = ${MY_PORT}\n").server_port == 9123


def test_unknown_reference_expands_to_nothing_with_an_error(caplog: pytest.LogCaptureFixture) -> None:
    mission = MissionFile.from_text("Community = x${NOT_DEFINED_ANYWHERE_42}y\n")
    assert mission.community == "xy"
    assert "NOT_DEFINED_ANYWHERE_42" in caplog.text


def test_missing_file_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(MissionFileError, match="cannot read mission file"):
        MissionFile(tmp_path / "absent.moos")


def test_block_without_brace_is_an_error() -> None:
    mission = MissionFile.from_text("ProcessConfig = a\n  x = 1\n")
    with pytest.raises(MissionFileError, match="not followed by"):
        mission.process_config("a")


def test_non_numeric_port_is_an_error() -> None:
    with pytest.raises(MissionFileError, match="ServerPort"):
        _ = MissionFile.from_text("ServerPort = abc\n").server_port
