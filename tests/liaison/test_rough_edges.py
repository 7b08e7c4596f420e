"""Issue 29's rough edges of the commander, below the browser (tests/launch/test_liaison_rough_edges.py has the
pages): the link's latency goes to the page with its unit, and the server rounds a value as DCCL's codec carries
it (integers: remainder toward zero, as C++), so the page's "sent as" note and the server agree with the wire."""

from __future__ import annotations

import asyncio
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import aiohttp
import pytest
from google.protobuf import text_format

from gateway.goby.dccl import Codec
from gateway.goby.intervehicle.testing import broker_config, link_block, random_multicast
from gateway.goby.portal.testing import broker_process, running_app
from launch.liaison.errors import CommandRefused
from launch.liaison.form_values import build_command
from launch.liaison.portal_side import LiaisonApp
from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
from tests.liaison.test_server import COMMANDER_CONFIG_HEAD, receive_until, ws_url
from tests.markers import needs_loopback_multicast
from tests.protobuf.dccl_test_pb2 import Everything
from util.process import free_port

INTERVEHICLE_CONFIG = COMMANDER_CONFIG_HEAD + """\
                   publish_to {{ group: "usv_command" group_numeric: 0 layer: LAYER_INTERVEHICLE }} }}
}}
"""
LATENCY = re.compile(r"(?<![\w.])latency: (\S+)( \S+)?")


@pytest.fixture
def topside(tmp_path: Path) -> Iterator[LiaisonApp]:
    """A topside broker with the course's satellite link (modem 1) and a goby-liaison on it; no USV anywhere, so a
    command expires (EXPIRED_NO_SUBSCRIBERS) with the link's latency (int64 microseconds in ExpireData)."""
    group, port = random_multicast()
    cfg_file = tmp_path / "topside.pb.cfg"
    cfg_file.write_text(broker_config([link_block(1, group, port, [(1, 5, 64), (2, 5, 64)])], warp=20))
    with broker_process(tmp_path, platform="topside", extra_args=[str(cfg_file)]) as broker:
        cfg = text_format.Parse(INTERVEHICLE_CONFIG.format(port=free_port()), LiaisonConfig())
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        with running_app(LiaisonApp, cfg) as app:
            yield app


@needs_loopback_multicast
def test_the_expiry_reaches_the_page_with_its_latency_in_ms_or_s(topside: LiaisonApp) -> None:
    async def scenario() -> dict[str, Any]:
        async with aiohttp.ClientSession() as session, session.ws_connect(ws_url(topside)) as ws:
            await ws.send_json({"op": "subscribe", "views": ["commander"]})
            await receive_until(ws, lambda m: m["op"] == "commands")
            await ws.send_json({"op": "send", "type": "goby3_course.dccl.USVCommand", "target": 0,
                                "values": {"desired_state": "WAYPOINTS"}, "comment": "to the first waypoint"})
            accepted = await receive_until(ws, lambda m: m["op"] in ("accepted", "refused", "error"))
            assert accepted["op"] == "accepted", accepted
            done = await receive_until(ws, lambda m: m["op"] == "sent" and any(
                e["id"] == accepted["id"] and e["state"] == "expired" for e in m["entries"]), 30)
            return next(e for e in done["entries"] if e["id"] == accepted["id"])

    entry = asyncio.run(scenario())
    assert entry["comment"] == "to the first waypoint"
    expiry = entry["acks"][-1]
    assert expiry.startswith("Expire: ") and "EXPIRED_NO_SUBSCRIBERS" in expiry, expiry
    (found,) = LATENCY.findall(expiry)
    value, unit = found
    assert unit in (" ms", " s") and float(value) >= 0, expiry  # not the wire's bare microseconds


@pytest.mark.parametrize(("typed", "carried"), [(-1060, -1000), (-1049, -1000), (-1040, -1000), (950, 1000),
                                                (949, 900), (-50, 0)])
def test_an_integer_is_rounded_as_the_codec_carries_it(typed: int, carried: int) -> None:
    """i32: [-1000, 1000], precision -2 (steps of 100); DCCL takes the remainder toward zero, so -1060 goes as
    -1000 (inside the bounds), where rounding half up (-1100) would refuse it."""
    msg = build_command(Everything, {"i32": typed}, now=lambda: 0.0)
    assert isinstance(msg, Everything) and msg.i32 == carried
    codec = Codec()
    codec.load(Everything)
    wire = codec.decode(codec.encode(Everything(i32=typed)))
    assert isinstance(wire, Everything) and wire.i32 == carried  # what the wire carries


def test_an_integer_beyond_the_bounds_after_rounding_is_refused() -> None:
    with pytest.raises(CommandRefused, match=r"i32: 1050 is outside its DCCL bounds \[-1000, 1000\], in steps of 100"):
        build_command(Everything, {"i32": 1050}, now=lambda: 0.0)
