"""goby-liaison's Commander on LAYER_INTERVEHICLE, on a goby-broker hosting a satellite link nobody else is on:
the command goes out through the intervehicle layer, its DCCL echo on interprocess shows as text in the scope, and
the link's expiry (no subscriber) is the command's state in the history. The ack path runs on the USV mission
(tests/launch/test_liaison_browser.py)."""

from __future__ import annotations

import asyncio

import aiohttp
import pytest
from google.protobuf import text_format

from gateway.goby.intervehicle.testing import (
    broker_config,
    link_block,
    loopback_multicast_works,
    random_multicast,
)
from gateway.goby.portal.testing import broker_process, running_app
from launch.config import free_tcp_port
from launch.liaison.portal_side import LiaisonApp
from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
from tests.liaison.test_server import receive_until, ws_url

pytestmark = pytest.mark.skipif(not loopback_multicast_works(), reason="multicast on 127.0.0.1 is not available here")

CONFIG = """
http_address: "127.0.0.1"
http_port: {port}
update_freq: 20
load_shared_library: "libgoby3_course_messages.so"
pb_commander_config {{
  load_protobuf {{ name: "goby3_course.dccl.USVCommand"
                   publish_to {{ group: "usv_command" group_numeric: 0 layer: LAYER_INTERVEHICLE }} }}
}}
"""


def test_intervehicle_command_expires_without_subscriber_and_its_echo_is_decoded(tmp_path):
    group, port = random_multicast()
    cfg_file = tmp_path / "topside.pb.cfg"
    cfg_file.write_text(broker_config([link_block(1, group, port, [(1, 5, 64), (2, 5, 64)])], warp=20))
    with broker_process(tmp_path, platform="topside", extra_args=[str(cfg_file)]) as broker:
        cfg = text_format.Parse(CONFIG.format(port=free_tcp_port()), LiaisonConfig())
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        with running_app(LiaisonApp, cfg) as app:

            async def scenario():
                async with aiohttp.ClientSession() as session, session.ws_connect(ws_url(app)) as ws:
                    await ws.send_json({"op": "subscribe", "views": ["commander", "scope"]})
                    catalogue = await receive_until(ws, lambda m: m["op"] == "commands")
                    (kind,) = catalogue["types"]
                    assert kind["targets"] == [{"index": 0, "label": "usv_command/0 [intervehicle]",
                                                "layer": "intervehicle"}]
                    await ws.send_json({"op": "send", "type": "goby3_course.dccl.USVCommand", "target": 0,
                                        "values": {"desired_state": "POLYGON", "polygon_sides": 8,
                                                   "polygon_radius": 400}})
                    accepted = await receive_until(ws, lambda m: m["op"] in ("accepted", "refused", "error"))
                    assert accepted["op"] == "accepted", accepted
                    expired = await receive_until(ws, lambda m: m["op"] == "sent" and any(
                        e["id"] == accepted["id"] and e["state"] == "expired" for e in m["entries"]), 30)
                    entry = next(e for e in expired["entries"] if e["id"] == accepted["id"])
                    assert entry["acks"][-1].startswith("Expire: ") and "EXPIRED_NO_SUBSCRIBERS" in entry["acks"][-1]
                    row = await receive_until(ws, lambda m: m["op"] == "scope" and any(
                        r["group"] == "usv_command;0" and r["scheme"] == "DCCL" for r in m["rows"]), 30)
                    dccl = next(r for r in row["rows"] if r["group"] == "usv_command;0" and r["scheme"] == "DCCL")
                    assert dccl["ok"] and "desired_state: POLYGON" in dccl["value"], dccl
                    assert "polygon_sides: 8" in dccl["value"] and "polygon_radius: 400" in dccl["value"]

            asyncio.run(scenario())
