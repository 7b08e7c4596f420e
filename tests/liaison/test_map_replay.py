"""Replay over the page's WebSocket: only a listed log opens (never a path), every number is range-checked, a log
larger than replay_max_samples is cut (and the page told), and the map's snapshot carries the command tool."""

from __future__ import annotations

import asyncio

import aiohttp
import pytest

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, VehicleType
from gateway.goby.log.writer import LogWriter
from gateway.goby.portal.marshalling import Scheme
from launch.liaison.map_model import NODE_STATUS_TYPE
from tests.liaison.test_server import COMMANDER_CONFIG_HEAD, liaison_on_broker, receive_until, ws_url

T0 = 1_700_000_000.0
SECONDS = 1500  # one sample per vehicle per second: 3000 samples, more than replay_max_samples
CONFIG = COMMANDER_CONFIG_HEAD + """\
                   publish_to {{ group: "goby3_course::shore::usv_command;0" layer: LAYER_INTERPROCESS }} }}
}}
[goby_moos_py.liaison.protobuf.web] {{ map {{ replay_dir: "{replay}" replay_max_samples: 1000 }} }}
"""


def write_log(path) -> None:
    with open(path, "wb") as f:
        writer = LogWriter(f.write, lambda: int(T0 * 1e6))
        for k in range(SECONDS):
            for name, x in (("usv", float(k)), ("auv_0", -float(k))):
                msg = NodeStatus(name=name, type=VehicleType.USV if name == "usv" else VehicleType.AUV, time=T0 + k)
                msg.local_fix.x, msg.local_fix.y = x, 0.0
                msg.global_fix.lat, msg.global_fix.lon = 41.5, -70.6
                msg.pose.heading, msg.speed.over_ground = 90.0, 1.0
                writer.write(msg.SerializeToString(), Scheme.PROTOBUF, NODE_STATUS_TYPE, "node_status",
                             int((T0 + k) * 1e6))


@pytest.fixture
def replay_site(tmp_path):
    folder = tmp_path / "logs"
    folder.mkdir()
    write_log(folder / "run.goby")
    (folder / "notes.txt").write_text("not a log")
    (tmp_path / "secret.goby").write_bytes(b"outside the folder")
    config = CONFIG.replace("{replay}", str(folder))
    with liaison_on_broker(tmp_path, config) as (app, _client):
        yield app


async def ask(ws, request: dict, ops: tuple[str, ...] = ("error",)) -> dict:
    await ws.send_json(request)
    return await receive_until(ws, lambda m: m["op"] in ops)


def test_replay_opens_listed_logs_only_checks_every_number_and_is_bounded(replay_site):
    app = replay_site

    async def scenario():
        async with aiohttp.ClientSession() as session, session.ws_connect(ws_url(app)) as ws:
            await ws.send_json({"op": "subscribe", "views": ["map"]})
            snapshot = await receive_until(ws, lambda m: m["op"] == "map" and m.get("full"))
            assert snapshot["replay"] is True
            assert snapshot["command"]["type"] == "goby3_course.dccl.USVCommand"
            assert snapshot["command"]["sides"] == [3, 10] and snapshot["command"]["radius"] == [100, 2000]
            listed = await ask(ws, {"op": "replay_list"}, ("replay_list",))
            assert [log["name"] for log in listed["logs"]] == ["run.goby"]  # no .txt, nothing outside

            seek_first = await ask(ws, {"op": "replay_seek", "t": T0})
            assert "no log is open" in seek_first["error"]
            for name in ("../secret.goby", "/etc/passwd", "notes.txt", "x" * 5000, 12):
                refused = await ask(ws, {"op": "replay_open", "name": name}, ("replay_error", "error"))
                assert refused["op"] in ("replay_error", "error"), refused
                assert "no log" in refused["error"] or '"name"' in refused["error"], refused

            opened = await ask(ws, {"op": "replay_open", "name": "run.goby"}, ("replay_opened", "replay_error"))
            assert opened["op"] == "replay_opened", opened
            assert opened["samples"] == 1000 and opened["dropped"] == 2 * SECONDS - 1000  # bounded, and said
            assert opened["vehicles"] == ["auv_0", "usv"] and opened["t0"] == T0

            frame = await ask(ws, {"op": "replay_seek", "t": T0 + 100, "trail_s": 10}, ("replay_frame",))
            positions = {v["name"]: (v["x"], len(v["trail"])) for v in frame["vehicles"]}
            assert positions == {"usv": (100.0, 11), "auv_0": (-100.0, 11)}
            late = await ask(ws, {"op": "replay_seek", "t": T0 + 10_000}, ("replay_frame",))
            assert late["t"] == opened["t1"]  # clamped to the log

            for bad in ({"t": "soon"}, {"t": True}, {"t": 1e400}, {"t": 1e300}, {}, {"t": T0, "trail_s": -1},
                        {"t": T0, "trail_s": 1e9}):
                error = await ask(ws, {"op": "replay_seek", **bad})
                assert '"t' in error["error"] or "Infinity is not a number" in error["error"], (bad, error)
            closed = await ask(ws, {"op": "replay_close"}, ("replay_closed",))
            assert closed["op"] == "replay_closed"

    asyncio.run(scenario())
