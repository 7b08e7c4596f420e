"""The operator's map in real headless Chromium, on a liaison of its own (a real broker, NodeStatus published by a
test client, a .goby log to replay): zoom and pan, the cursor's lat/lon, range and bearing, vehicles by type, the
mode before any command, and replay.  The map on the running missions is tested in test_liaison_browser.py (the
helm's polygon, commands from the map) and test_trail_mission.py (the topside's fleet)."""

from __future__ import annotations

import contextlib
import math
import re
import struct
import sys
import urllib.request
import zlib

import pytest

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, VehicleType
from gateway.goby.log.writer import LogWriter
from gateway.goby.portal.marshalling import Scheme
from gateway.goby.portal.testing import PortalClient, broker_process
from launch.liaison.map_model import NODE_STATUS_TYPE
from launch.liaison.portal_side import READY_PREFIX
from launch.liaison.testing import browser_skip_reason, chromium
from util.geodesy import UTMGeodesy
from util.process import ChildProcess, free_port, wait_until

SKIP = browser_skip_reason()
pytestmark = pytest.mark.skipif(SKIP is not None, reason=str(SKIP))

DATUM = (41.52, -70.68)
CONFIG = """
interprocess {{ {interprocess} }}
http_address: "127.0.0.1"
http_port: {port}
update_freq: 10
[goby_moos_py.liaison.protobuf.web] {{
  map {{
    loiter_polygon {{ x: -100 y: -100 }} loiter_polygon {{ x: 100 y: -100 }} loiter_polygon {{ x: 100 y: 100 }}
    loiter_polygon {{ x: -100 y: 100 }}
    initial_mode: "POLYGON"
    datum_lat: {lat} datum_lon: {lon}
    replay_dir: "{replay}"
    background {{ image: "{image}" lat_north: {north} lat_south: {south} lon_east: {east} lon_west: {west} }}
  }}
}}
"""
T0 = 1_700_000_000.0


def node_status(name: str, kind: int, x: float, y: float, heading: float = 45.0, t: float = T0) -> NodeStatus:
    status = NodeStatus(name=name, type=kind, time=t)
    status.local_fix.x, status.local_fix.y = x, y
    status.global_fix.lat, status.global_fix.lon = UTMGeodesy(*DATUM).to_geo(x, y)
    status.pose.heading, status.speed.over_ground = heading, 1.5
    return status


def png(width: int, height: int) -> bytes:
    """A small solid PNG (no imaging library needed)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    rows = b"".join(b"\x00" + b"\x90\xc0\xe0" * width for _ in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def write_log(path) -> list[tuple[float, str, float, float]]:
    """A .goby log of two vehicles for 100 s (one NodeStatus each per second); the (t, name, x, y) written."""
    written = []
    with open(path, "wb") as f:
        writer = LogWriter(f.write, lambda: int(T0 * 1e6))
        for k in range(101):
            t = T0 + k
            for name, kind, x, y in (("usv", VehicleType.USV, 5.0 * k, 0.0), ("auv_1", VehicleType.AUV, 0.0, -3.0 * k)):
                writer.write(node_status(name, kind, x, y, t=t).SerializeToString(), Scheme.PROTOBUF,
                             NODE_STATUS_TYPE, f"{name}::node_status", int(t * 1e6))
                written.append((t, name, x, y))
    return written


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("liaison_map")
    replay = tmp / "logs"
    (replay / "usv").mkdir(parents=True)
    logged = write_log(replay / "usv" / "usv_20260101T000000.goby")
    with contextlib.ExitStack() as stack:
        broker = stack.enter_context(broker_process(tmp, platform="map"))
        port = free_port()
        config = tmp / "liaison.pb.cfg"
        image = tmp / "area.png"
        image.write_bytes(png(4, 4))
        north, east = UTMGeodesy(*DATUM).to_geo(200.0, 300.0)
        south, west = UTMGeodesy(*DATUM).to_geo(-200.0, -300.0)
        config.write_text(CONFIG.format(interprocess=broker.interprocess_text(), port=port, lat=DATUM[0],
                                        lon=DATUM[1], replay=replay, image=image, north=north, south=south,
                                        east=east, west=west))
        liaison = ChildProcess([sys.executable, "-m", "launch.apps.goby_liaison", str(config)], tmp / "liaison.log",
                               name="goby-liaison")
        liaison.start().wait_ready(re.escape(READY_PREFIX), timeout=30)
        stack.callback(liaison.stop)
        client = stack.enter_context(PortalClient(broker.interprocess_config()))
        client.wait_subscribed()
        client.publish("usv::node_status", node_status("usv", VehicleType.USV, 150.0, 50.0))
        client.publish("auv_1::node_status", node_status("auv_1", VehicleType.AUV, -120.0, -60.0, heading=200.0))
        driver = stack.enter_context(chromium())
        yield f"http://127.0.0.1:{port}/?_=/map", driver, logged


def open_map(url, driver) -> None:
    driver.get(url)
    wait_until(lambda: set(driver.execute_script("return Object.keys(LiveMap.drawn.vehicles)")) == {"usv", "auv_1"},
               what="both vehicles drawn")


def extent(driver) -> list[float]:
    return [float(v) for v in driver.find_element("id", "map").get_attribute("data-extent").split()]


def test_zoom_and_pan_change_the_view_extent(site):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.actions.wheel_input import ScrollOrigin
    from selenium.webdriver.common.keys import Keys

    url, driver, _ = site
    open_map(url, driver)
    canvas = driver.find_element("id", "map")
    first = extent(driver)
    width = first[2] - first[0]
    assert first[0] < -120 and first[2] > 150 and first[1] < -100 and first[3] > 100  # fitted to everything

    ActionChains(driver).scroll_from_origin(ScrollOrigin.from_element(canvas), 0, -100).perform()
    zoomed = wait_until(lambda: (e := extent(driver)) and e[2] - e[0] < width * 0.9 and e, what="wheel zoom")
    canvas.click()  # focus
    ActionChains(driver).send_keys("-").send_keys("-").perform()
    out = wait_until(lambda: (e := extent(driver)) and e[2] - e[0] > (zoomed[2] - zoomed[0]) * 1.4 and e,
                     what="zoom out by key")
    ActionChains(driver).send_keys(Keys.ARROW_RIGHT).perform()
    panned = wait_until(lambda: (e := extent(driver)) and e[0] > out[0] + 1 and e, what="pan by key")
    assert math.isclose(panned[2] - panned[0], out[2] - out[0], rel_tol=1e-6)  # a pan keeps the scale
    ActionChains(driver).click_and_hold(canvas).move_by_offset(0, 120).release().perform()
    dragged = wait_until(lambda: (e := extent(driver)) and e[3] > panned[3] + 1 and e, what="drag pan")
    assert math.isclose(dragged[0], panned[0], abs_tol=1e-6)  # dragged down: the view moved north only


def test_cursor_shows_local_and_geographic_coordinates(site):
    from selenium.webdriver.common.action_chains import ActionChains

    url, driver, _ = site
    open_map(url, driver)
    canvas = driver.find_element("id", "map")
    ActionChains(driver).move_to_element_with_offset(canvas, 40, -30).perform()
    text = wait_until(lambda: (t := driver.find_element("id", "map-cursor").text) and "°" in t and t,
                      what="the cursor's coordinates")
    x, y, lat, lon = (float(v) for v in re.findall(r"-?\d+\.\d+", text))
    true_lat, true_lon = UTMGeodesy(*DATUM).to_geo(x, y)
    assert abs(lat - true_lat) < 2e-6 and abs(lon - true_lon) < 2e-6, (text, true_lat, true_lon)


def test_vehicles_by_type_and_the_mode_before_any_command(site):
    url, driver, _ = site
    open_map(url, driver)
    rows = driver.execute_script("return [...document.querySelectorAll('#vehicle-table tbody tr')]"
                                 ".map(r => r.children[0].textContent)")
    assert sorted(rows) == ["auv_1 (AUV)", "usv (USV)"]
    assert driver.find_element("id", "map-mode").text.startswith("POLYGON")  # not "unknown" before a command
    drawn = driver.execute_script("return LiveMap.drawn.vehicles")
    assert drawn == {"usv": [150, 50], "auv_1": [-120, -60]}


def test_range_and_bearing_between_two_clicks(site):
    from selenium.webdriver.common.action_chains import ActionChains

    url, driver, _ = site
    open_map(url, driver)
    canvas = driver.find_element("id", "map")
    driver.find_element("id", "map-measure-tool").click()
    ActionChains(driver).move_to_element_with_offset(canvas, 0, 0).click().move_by_offset(60, -80).click().perform()
    text = wait_until(lambda: (t := driver.find_element("id", "map-measure").text) and "at" in t and t,
                      what="the measure")
    scale = driver.execute_script("return LiveMap.view.scale")
    distance, bearing = (float(v) for v in re.findall(r"\d+\.\d+", text))
    assert math.isclose(distance, 100 / scale, rel_tol=0.02), (text, scale)  # 60-80-100 px
    assert math.isclose(bearing, math.degrees(math.atan2(60, 80)), abs_tol=1.0)  # east of north
    driver.find_element("id", "map-measure-tool").click()


def test_replay_slider_moves_the_vehicles_to_their_logged_positions(site):
    url, driver, logged = site
    open_map(url, driver)
    driver.find_element("id", "replay-refresh").click()
    wait_until(lambda: driver.find_elements("css selector", "#replay-log option"), what="the list of logs")
    assert driver.find_element("id", "replay-log").get_attribute("value") == "usv/usv_20260101T000000.goby"
    driver.find_element("id", "replay-open").click()
    wait_until(lambda: "replaying" in driver.find_element("id", "replay-status").text, what="the log opened")
    for target in (T0 + 20, T0 + 73):
        driver.execute_script("const s = document.getElementById('replay-slider'); s.value = arguments[0];"
                              "s.dispatchEvent(new Event('input'))", target)
        expected = {name: [x, y] for t, name, x, y in logged if t == target}
        wait_until(lambda e=expected: driver.execute_script("return LiveMap.drawn.vehicles") == e,
                   what=f"the vehicles at +{target - T0:.0f} s")
    driver.find_element("id", "replay-live").click()
    wait_until(lambda: driver.execute_script("return LiveMap.drawn.vehicles") == {"usv": [150, 50],
                                                                                  "auv_1": [-120, -60]},
               what="the live vehicles back")


def test_the_background_image_is_served_by_the_liaison_at_its_corners(site):
    url, driver, _ = site
    open_map(url, driver)
    with urllib.request.urlopen(url.split("/?")[0] + "/map/background") as response:
        assert response.headers["Content-Type"] == "image/png" and response.read() == png(4, 4)
    wait_until(lambda: driver.execute_script("return LiveMap.backgroundImage && LiveMap.backgroundImage.naturalWidth")
               == 4, what="the image loaded by the page")
    edges = driver.execute_script("return LiveMap.background")
    assert edges["west"] == pytest.approx(-200, abs=1) and edges["north"] == pytest.approx(300, abs=1)
