"""The trail demo on lossy links (issue 25): ``python -m launch.trail.demo`` with the channel flags, one AUV, warp 20.

The flags reach every node's generated link config (each broker logs its simulated channel); the summary prints the
channels and, per link, the commands sent, acked and expired; every command is acked or reported expired to its
publisher (sent = acked + expired); bad channel flags are refused by the parser, naming the flag."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from launch.errors import MissionConfigError
from launch.process_group import child_environment
from launch.trail.config import link_block
from launch.trail.demo import build_parser, channel_settings
from launch.trail.settings import TrailSettings, Vehicle
from tests.markers import needs_loopback_multicast

NEEDED = ("auv-manager", "topside-manager", "usv-manager")
CHANNEL_FLAGS = ["--acomms-loss", "0.2", "--acomms-delay", "1-3", "--satellite-loss", "0.05", "--satellite-outage",
                 "30", "--channel-seed", "3"]
ACCOUNT = re.compile(r"^  (satellite|acomms) \((.*)\): (\d+) sent x (\d+) recipients? = (\d+): (\d+) acked, "
                     r"(\d+) expired(.*)$", re.M)


def test_channel_flags_reach_the_link_configs() -> None:
    args = build_parser().parse_args(CHANNEL_FLAGS)
    channels = channel_settings(args)
    assert channels == {"satellite": "loss: 0.05 outage_period: 300 outage_duration: 30 seed: 3",
                        "acomms": "loss: 0.2 delay_min: 1 delay_max: 3 seed: 3"}
    settings = TrailSettings(acomms_channel=channels["acomms"], satellite_channel=channels["satellite"])
    again = TrailSettings.from_env(settings.to_env())  # as every launch line rebuilds them
    block = link_block(again, Vehicle("usv", 1), "acomms")
    assert "[goby_moos_py.acomms.protobuf.channel_model] { loss: 0.2 delay_min: 1.0 delay_max: 3.0 seed: 3 }" in block
    assert "channel_model" not in link_block(TrailSettings(), Vehicle("usv", 1), "acomms")  # lossless: no model
    with pytest.raises(MissionConfigError, match=r"TRAIL_ACOMMS_CHANNEL=.*channel_model\.loss"):
        TrailSettings.from_env({"TRAIL_ACOMMS_CHANNEL": "loss: 1.5"})


@pytest.mark.parametrize(("flags", "named"), [
    (["--acomms-loss", "1.2"], "--acomms-loss"),
    (["--satellite-delay", "3-1"], "--satellite-delay"),
    (["--acomms-delay", "nan"], "--acomms-delay"),
    (["--satellite-outage", "30/10"], "--satellite-outage"),
    (["--channel-seed", "-1"], "--channel-seed"),
])
def test_bad_channel_flags_are_refused_naming_the_flag(flags: list[str], named: str,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        build_parser().parse_args(flags)
    assert exit_info.value.code == 2
    assert f"argument {named}: " in capsys.readouterr().err


@needs_loopback_multicast
@pytest.mark.skipif(any(shutil.which(p, path=child_environment()["PATH"]) is None for p in NEEDED),
                    reason=f"the course's managers ({', '.join(NEEDED)}) are not installed yet")
def test_lossy_trail_mission_acks_or_expires_every_command(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "launch.trail.demo", "--auvs", "1", "--warp", "20", "--duration", "300",
         "--schedule", "0:polygon:6:200,20:waypoints,40:recover", "--moosdb", "ours", "--helm", "ours",
         "--out", str(tmp_path), *CHANNEL_FLAGS],
        capture_output=True, text=True, timeout=300)
    out = result.stdout
    assert result.returncode == 0, out + result.stderr
    described = "satellite loss 5%, outage 30 s every 300 s, seed 3; acomms loss 20%, delay 1-3 s, seed 3"
    assert f"channels: {described}" in out and "channels (simulated on receive by each modem driver" in out, out
    accounts = {m[0]: m for m in ACCOUNT.findall(out)}
    assert set(accounts) == {"satellite", "acomms"}, out
    for link, (_, _, sent, recipients, deliveries, acked, expired, tail) in accounts.items():
        assert int(sent) == (2 if link == "satellite" else 1) and int(recipients) == 1, out
        assert int(deliveries) == int(acked) + int(expired), out  # nothing silent
        assert "UNSETTLED" not in tail, out
    assert "RECOVER never reached" not in out, out
    logs = {p.name: p.read_text() for p in (tmp_path / "run" / "logs" / "launch").rglob("*.goby-broker.log")}
    simulated = [line for text in logs.values() for line in text.splitlines() if "SIMULATED channel" in line]
    assert len(simulated) == 4, logs.keys()  # topside: satellite; USV: both; AUV: acomms
    assert sum("loss 20%, delay 1-3 s" in line for line in simulated) == 2, simulated
