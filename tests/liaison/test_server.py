"""goby-liaison on a real broker, driven over its WebSocket: updates, commands, and every kind of bad input."""

from __future__ import annotations

import asyncio
import contextlib
import json
import socket
import time

import aiohttp
import pytest
from google.protobuf import text_format

from gateway.goby.portal.testing import PortalClient, broker_process, running_app
from launch.liaison.portal_side import LiaisonApp
from launch.liaison.protobuf import liaison_web_pb2  # noqa: F401 - the [..web] extension
from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
from translators.usv import groups as usv_groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from util.process import free_port

# How every test's config begins: the page on loopback, the course's messages, the Commander's USVCommand.
COMMANDER_CONFIG_HEAD = """
http_address: "127.0.0.1"
http_port: {port}
update_freq: 20
load_shared_library: "libgoby3_course_messages.so"
pb_commander_config {{
  load_protobuf {{ name: "goby3_course.dccl.USVCommand"
"""
CONFIG = COMMANDER_CONFIG_HEAD + """\
                   publish_to {{ group: "goby3_course::shore::usv_command;0" layer: LAYER_INTERPROCESS }} }}
  notify_subscribe {{ type_regex: ".*USVCommandAck" group_regex: ".*" }}
}}
[goby_moos_py.liaison.protobuf.web] {{
  client_queue_updates: 4
  max_clients: 60
  interprocess_ack {{ command_type: "goby3_course.dccl.USVCommand" ack_type: "goby_moos_py.usv.protobuf.USVCommandAck"
                      ack_group: "goby3_course::usv_command_ack" command_field: "time" ack_field: "command_time"
                      final_field: "stage" final_value: "POSTED_TO_MOOS" refused_value: "REFUSED" timeout: 2 }}
}}
"""


@contextlib.contextmanager
def liaison_on_broker(tmp_path, config: str = CONFIG):
    """A liaison (``config`` with ``{port}``) and a test client on a fresh broker."""
    with broker_process(tmp_path, platform="web") as broker:
        cfg = text_format.Parse(config.format(port=free_port()), LiaisonConfig())
        cfg.interprocess.CopyFrom(broker.interprocess_config())
        with running_app(LiaisonApp, cfg) as app, PortalClient(broker.interprocess_config()) as client:
            client.wait_subscribed()
            yield app, client


@pytest.fixture
def liaison(tmp_path):
    with liaison_on_broker(tmp_path) as pair:
        yield pair


def ws_url(app: LiaisonApp) -> str:
    return f"http://127.0.0.1:{app.web.port}/ws"


async def receive_until(ws, predicate, timeout_s: float = 10.0):
    """The first message for which ``predicate(msg)`` is true."""
    deadline = time.monotonic() + timeout_s
    while True:
        msg = await asyncio.wait_for(ws.receive_json(), max(0.01, deadline - time.monotonic()))
        if predicate(msg):
            return msg


BURST = 300  # publications per group in the scope test: 600 in all, more than max_history_items (100)


def test_scope_rows_arrive_coalesced_and_filtered(liaison):
    app, client = liaison

    async def scenario():
        async with aiohttp.ClientSession() as session, session.ws_connect(ws_url(app)) as ws:
            await ws.send_json({"op": "subscribe", "views": ["scope"]})
            # A burst well inside the broker's per-subscriber queue (send_queue_size 1000): a burst at the
            # high-water mark loses its tail at the broker while the page's thread is starved, as with gobyd.
            for i in range(BURST):
                client.publish("fast::group", f"value {i}")
                client.publish("other", "x")
            client.poll(0.01)
            row = await receive_until(ws, lambda m: m["op"] == "scope" and any(
                r["group"] == "fast::group" and r["count"] == BURST for r in m["rows"]))
            fast = next(r for r in row["rows"] if r["group"] == "fast::group")
            assert fast["value"] == f"value {BURST - 1}" and fast["scheme"] == "CSTR" and fast["type"] == "CSTR"
            await ws.send_json({"op": "filter", "group": "fast::.*", "type": ".*"})
            full = await receive_until(ws, lambda m: m["op"] == "scope" and m["full"])
            assert {r["group"] for r in full["rows"]} == {"fast::group"}
            await ws.send_json({"op": "expand", "id": fast["id"]})
            history = await receive_until(ws, lambda m: m["op"] == "history")
            assert [h["value"] for h in history["items"][:2]] == [f"value {BURST - 1}", f"value {BURST - 2}"]
            assert len(history["items"]) == 100  # max_history_items

    asyncio.run(scenario())


def test_command_is_published_and_acknowledged(liaison):
    app, client = liaison
    commands = client.collect(usv_groups.shore_usv_command, USVCommand)
    client.wait_subscribed()

    async def scenario():
        async with aiohttp.ClientSession() as session, session.ws_connect(ws_url(app)) as ws:
            await ws.send_json({"op": "subscribe", "views": ["commander"]})
            catalogue = await receive_until(ws, lambda m: m["op"] == "commands")
            assert [t["name"] for t in catalogue["types"]] == ["goby3_course.dccl.USVCommand"]
            assert catalogue["types"][0]["targets"][0]["label"] == "goby3_course::shore::usv_command;0 [interprocess]"
            await ws.send_json({"op": "send", "type": "goby3_course.dccl.USVCommand", "target": 0,
                                "values": {"desired_state": "POLYGON", "polygon_sides": 8, "polygon_radius": 400}})
            accepted = await receive_until(ws, lambda m: m["op"] in ("accepted", "refused"))
            assert accepted["op"] == "accepted", accepted
            assert client.poll_until(lambda: bool(commands), 10)
            sent = commands[0]
            assert sent.polygon_sides == 8 and sent.polygon_radius == 400
            client.publish(usv_groups.usv_command_ack, USVCommandAck(
                stage=USVCommandAck.POSTED_TO_MOOS, command_time=sent.time, responder="test"))
            acked = await receive_until(ws, lambda m: m["op"] == "sent" and m["entries"][0]["state"] == "acknowledged")
            assert "POSTED_TO_MOOS" in acked["entries"][0]["acks"][0]
            notice = await receive_until(ws, lambda m: m["op"] == "notify")
            assert notice["items"][0]["type"] == "goby_moos_py.usv.protobuf.USVCommandAck"
            # A second command nobody acknowledges expires after the configured timeout (2 s).
            await ws.send_json({"op": "send", "type": "goby3_course.dccl.USVCommand", "target": 0,
                                "values": {"desired_state": "WAYPOINTS"}})
            expired = await receive_until(ws, lambda m: m["op"] == "sent" and m["entries"][0]["state"] == "expired")
            assert expired["entries"][0]["acks"] == ["no acknowledgement within the timeout"]

    asyncio.run(scenario())


BAD_REQUESTS = [
    ("not json", "message is not JSON"),
    ("[1, 2]", 'must be a JSON object with an "op" string'),
    ('{"op": "fly"}', "unknown op 'fly'"),
    ('{"op": "subscribe", "views": ["radar"]}', "unknown view(s) radar"),
    ('{"op": "filter", "group": "(", "type": ".*"}', "group filter '(' is not a valid regular expression"),
    ('{"op": "expand", "id": 99999}', "no scope row 99999"),
    ('{"op": "expand"}', "bad expand request"),
    ('{"op": "send", "type": "goby.Unknown", "target": 0}', "type 'goby.Unknown' is not in the configured list"),
    ('{"op": "send", "type": "goby3_course.dccl.USVCommand", "target": 3}', "target 3 is not a configured publish_to"),
    ('{"op": "send", "type": "goby3_course.dccl.USVCommand", "target": 0, "values": {"desired_state": "POLYGON", '
     '"polygon_radius": "5000"}}', "polygon_radius: 5000 is outside its DCCL bounds [100, 2000], in steps of 10"),
    ('{"op": "send", "type": "goby3_course.dccl.USVCommand", "target": 0, "values": {"desired_state": 7}}',
     "desired_state: 7 is not one of WAYPOINTS, POLYGON"),
]


def test_bad_requests_get_a_clear_answer_and_the_page_keeps_serving(liaison):
    app, client = liaison

    async def scenario():
        async with aiohttp.ClientSession() as session, session.ws_connect(ws_url(app)) as ws:
            for text, words in BAD_REQUESTS:
                await ws.send_str(text)
                reply = await receive_until(ws, lambda m: m["op"] in ("error", "refused"))
                assert words in reply["error"], (text, reply)
            await ws.send_bytes(b"\x00\x01")
            reply = await receive_until(ws, lambda m: m["op"] == "error")
            assert "binary messages are not understood" in reply["error"]
            # still serving: a good request works
            await ws.send_json({"op": "subscribe", "views": ["commander"]})
            await receive_until(ws, lambda m: m["op"] == "commands")
        async with aiohttp.ClientSession() as session:
            async with session.get(ws_url(app), headers={"Origin": "http://evil.example", "Connection": "Upgrade",
                                                         "Upgrade": "websocket"}) as response:
                assert response.status == 403 and "evil.example" in await response.text()

    asyncio.run(scenario())


def test_fifty_tabs_and_a_client_that_never_reads(liaison):
    """50 pages at once all get their data; a page that never reads loses its queued updates, nobody else does."""
    app, client = liaison
    stalled = socket.create_connection(("127.0.0.1", app.web.port))
    stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    stalled.sendall(b"GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                    b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n")
    # subscribe the stalled page to the scope, then never read again
    payload = json.dumps({"op": "subscribe", "views": ["scope"]}).encode()
    stalled.sendall(bytes([0x81, 0x80 | len(payload), 1, 2, 3, 4]) + bytes(b ^ (1, 2, 3, 4)[i % 4]
                                                                           for i, b in enumerate(payload)))
    try:
        async def scenario():
            async with aiohttp.ClientSession() as session:
                tabs = [await session.ws_connect(ws_url(app)) for _ in range(50)]
                for ws in tabs:
                    await ws.send_json({"op": "subscribe", "views": ["scope"]})
                big = "x" * 1500
                deadline = time.monotonic() + 20
                stalled_browser = None
                while time.monotonic() < deadline:
                    for i in range(200):
                        client.publish(f"bulk{i % 40}", f"{i} {big}")
                    client.poll(0.01)
                    for ws in tabs:  # the 50 good tabs read what they were sent
                        while True:
                            try:
                                await asyncio.wait_for(ws.receive(), 0.001)
                            except TimeoutError:
                                break
                    stalled_browser = next((b for b in app.web.browsers if b.dropped), None)
                    if stalled_browser is not None:
                        break
                    await asyncio.sleep(0.05)
                assert stalled_browser is not None, "the stalled page never overflowed its queue"
                assert sum(1 for b in app.web.browsers if b.dropped) == 1
                for ws in tabs:
                    await ws.send_json({"op": "pause"})
                    reply = await receive_until(ws, lambda m: m["op"] == "paused")
                    assert reply["paused"] is True
                    await ws.close()
            assert app.web.ticks > 0

        asyncio.run(scenario())
    finally:
        stalled.close()


def test_too_many_pages_and_a_taken_port_are_refused(liaison, tmp_path):
    app, _ = liaison
    app.web.settings.max_clients = 1

    async def scenario():
        async with aiohttp.ClientSession() as session, session.ws_connect(ws_url(app)):
            async with session.get(ws_url(app), headers={"Connection": "Upgrade", "Upgrade": "websocket"}) as second:
                assert second.status == 503 and "too many pages open" in await second.text()

    asyncio.run(scenario())
    cfg = text_format.Parse(CONFIG.format(port=app.web.port), LiaisonConfig())
    cfg.interprocess.CopyFrom(app.cfg().interprocess)
    with pytest.raises(Exception, match=rf"cannot serve http on 127.0.0.1:{app.web.port}"):
        with running_app(LiaisonApp, cfg):
            pass


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ('pb_commander_config { load_protobuf { name: "no.such.Type" } }', "load_protobuf[0].name: protobuf type"),
        ('load_shared_library: "libnothing.so"', "Failed to open protobuf message library: libnothing.so"),
        ('load_proto_file: "x.proto"', "load_proto_file is not supported here"),
        ('pb_scope_config { group_regex_filter_expression: "[" }', "group filter '[' is not a valid"),
        ('pb_commander_config { load_protobuf { name: "goby_moos_py.usv.protobuf.USVCommandAck" publish_to { '
         'group: "g" layer: LAYER_INTERVEHICLE } } } load_shared_library: "libgoby3_course_messages.so"',
         "USVCommandAck is not a DCCL message (LAYER_INTERVEHICLE sends DCCL only)"),
    ],
)
def test_bad_configs_are_refused_naming_the_field(extra, words):
    from launch.liaison.errors import LiaisonConfigError
    from launch.liaison.settings import load_settings

    with pytest.raises(LiaisonConfigError) as refused:
        load_settings(text_format.Parse(extra, LiaisonConfig()))
    assert words in str(refused.value)
