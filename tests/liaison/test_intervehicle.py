"""goby-liaison's Commander on LAYER_INTERVEHICLE, on a goby-broker hosting a satellite link nobody else is on (the
USV is not there): the command goes out through the intervehicle layer, its DCCL echo on interprocess shows as text
in the scope, and the link's expiry (no subscriber) is the command's state in the history, over the WebSocket and
in a real browser. The ack path runs on the USV mission (tests/launch/test_liaison_browser.py)."""

from __future__ import annotations

import asyncio

import aiohttp
import pytest
from google.protobuf import text_format

from gateway.goby.intervehicle.testing import broker_config, link_block, random_multicast
from gateway.goby.portal.testing import broker_process, running_app
from launch.liaison.portal_side import LiaisonApp
from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
from launch.liaison.settings import load_settings
from launch.liaison.testing import browser_skip_reason, chromium
from launch.trail.config import generate as trail_generate
from launch.trail.demo import liaison_urls_line
from launch.trail.settings import TrailSettings, Vehicle
from tests.liaison.test_server import COMMANDER_CONFIG_HEAD, receive_until, ws_url
from tests.markers import needs_loopback_multicast
from util.process import free_port, wait_until

pytestmark = needs_loopback_multicast

CONFIG = COMMANDER_CONFIG_HEAD + """\
                   publish_to {{ group: "usv_command" group_numeric: 0 layer: LAYER_INTERVEHICLE }} }}
}}
"""


@pytest.fixture
def topside(tmp_path):
    """A topside broker with the course's satellite link (modem 1) and a goby-liaison on it; no USV anywhere."""
    group, port = random_multicast()
    cfg_file = tmp_path / "topside.pb.cfg"
    cfg_file.write_text(broker_config([link_block(1, group, port, [(1, 5, 64), (2, 5, 64)])], warp=20))
    with broker_process(tmp_path, platform="topside", extra_args=[str(cfg_file)]) as broker:
        cfg = text_format.Parse(CONFIG.format(port=free_port()), LiaisonConfig())
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        with running_app(LiaisonApp, cfg) as app:
            yield app


def test_intervehicle_command_expires_without_subscriber_and_its_echo_is_decoded(topside):
    app = topside

    async def scenario():
        async with aiohttp.ClientSession() as session, session.ws_connect(ws_url(app)) as ws:
            await ws.send_json({"op": "subscribe", "views": ["commander", "scope"]})
            catalogue = await receive_until(ws, lambda m: m["op"] == "commands")
            (kind,) = catalogue["types"]
            assert kind["targets"] == [{"index": 0, "label": "usv_command/0 [intervehicle]", "layer": "intervehicle"}]
            await ws.send_json({"op": "send", "type": "goby3_course.dccl.USVCommand", "target": 0,
                                "values": {"desired_state": "POLYGON", "polygon_sides": 8, "polygon_radius": 400}})
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


@pytest.mark.skipif(browser_skip_reason() is not None, reason=str(browser_skip_reason()))
def test_the_page_shows_the_expiry_when_the_usv_is_not_there(topside):
    from selenium.webdriver.support.ui import Select

    with chromium() as browser:
        browser.get(f"http://127.0.0.1:{topside.web.port}/?_=/commander")
        wait_until(lambda: browser.find_elements("css selector", '[data-path="desired_state"]'), what="the form")
        Select(browser.find_element("css selector", '[data-path="desired_state"]')).select_by_value("WAYPOINTS")
        browser.find_element("id", "send").click()
        state = wait_until(lambda: (cell := browser.find_elements("css selector", "#sent-table tbody tr td.state"))
                           and cell[0].text == "expired" and cell[0], what="the expiry in the page")
        assert "state-expired" in state.get_attribute("class")
        text = state.find_element("xpath", "following-sibling::td").text
        assert text.startswith("Expire: ") and "EXPIRED_NO_SUBSCRIBERS" in text


def test_the_trail_topside_page_commands_over_intervehicle_and_the_demo_prints_it():
    settings = TrailSettings()
    topside = Vehicle("topside", 2)
    cfg = text_format.Parse(trail_generate("topside", "liaison", settings, topside), LiaisonConfig())
    assert cfg.http_port == 50000  # 50000 + platform id 0, as the course
    (kind,) = load_settings(cfg).command_types
    assert [t.label for t in kind.targets] == ["goby3_course::usv_command/0 [intervehicle]"]
    assert not load_settings(text_format.Parse(trail_generate("usv", "liaison", settings, Vehicle("usv", 2)),
                                               LiaisonConfig())).command_types
    line = liaison_urls_line(settings, 2)
    assert "topside http://127.0.0.1:50000/" in line and "auv1 http://127.0.0.1:50003/" in line
    assert line.endswith("http://127.0.0.1:50000/?_=/commander")
