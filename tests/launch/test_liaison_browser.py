"""goby-liaison in a real headless browser on the running USV mission: the lecture's scope and commander.

One mission (no shore schedule: the browser is the operator) and one browser serve every test in this module.
Set LIAISON_SCREENSHOT_DIR to keep the screenshots of the three views (docs/ holds the committed ones).
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
import time
from pathlib import Path

import pytest

from gateway.goby.acomms.udp_multicast import random_multicast
from launch.liaison.testing import browser_skip_reason, chromium
from launch.usv.analysis import command_effects
from launch.usv.geometry import Polygon, parse_polygon
from launch.usv.mission import UsvMission
from launch.usv.settings import UsvSettings
from util.process import free_port, wait_until

SKIP = browser_skip_reason()
pytestmark = pytest.mark.skipif(SKIP is not None, reason=str(SKIP))

FRONTSEAT_GROUPS = ["data_from_frontseat", "desired_course", "helm_state", "node_status", "raw_in", "raw_out",
                    "status"]
PREFIX = "goby::middleware::frontseat::"


@pytest.fixture(scope="module")
def mission(tmp_path_factory):
    run_dir = tmp_path_factory.mktemp("liaison_usv")
    socket_dir = Path(tempfile.mkdtemp(prefix="usvl-", dir="/tmp"))
    settings = UsvSettings(run_dir=run_dir, warp=20, moos_port=free_port(), sim_port=free_port(),
                           liaison_port=free_port(), schedule="none", socket_name=str(socket_dir / "goby_usv"),
                           sat_port=random_multicast()[1])
    lines: list[str] = []
    usv = UsvMission(settings, report=lines.append)
    try:
        usv.start()
        usv.urls = usv.liaison_urls()
        usv.wait_for_command()
        yield usv
    finally:
        result = usv.stop()
        shutil.rmtree(socket_dir, ignore_errors=True)
        assert result.log_errors == [], result.log_errors
        assert all(o.clean for o in result.outcomes), [o for o in result.outcomes if not o.clean]


@pytest.fixture(scope="module")
def browser():
    with chromium() as driver:
        yield driver


def screenshot(driver, name: str) -> None:
    target = os.environ.get("LIAISON_SCREENSHOT_DIR")
    if target:
        Path(target).mkdir(parents=True, exist_ok=True)
        driver.save_screenshot(str(Path(target) / f"liaison_{name}.png"))


def scope_counts(driver) -> dict[str, int]:
    """Visible scope rows: group -> count."""
    rows = driver.execute_script(
        "return [...document.querySelectorAll('#scope-table tbody tr.row')].map("
        "r => [r.children[0].textContent, r.children[5].textContent])")
    return {group: int(count) for group, count in rows}


def test_scope_shows_the_frontseat_groups_updating(mission, browser):
    browser.get(mission.urls["scope"])
    wanted = {PREFIX + g for g in FRONTSEAT_GROUPS}
    first = wait_until(lambda: (c := scope_counts(browser)) and wanted <= set(c) and c, what="the frontseat groups")
    later = wait_until(lambda: (c := scope_counts(browser)) and all(
        c[g] > first[g] for g in wanted - {PREFIX + "desired_course"}) and c, what="the counts to grow")
    assert later[PREFIX + "node_status"] > first[PREFIX + "node_status"]
    value = browser.execute_script(
        f"return [...document.querySelectorAll('#scope-table tr.row')].find(r => r.children[0].textContent == "
        f"'{PREFIX}node_status').children[3].textContent")
    assert "global_fix" in value and "local_fix" in value  # decoded, in text format
    screenshot(browser, "scope")


def test_a_filter_hides_the_others_and_pause_freezes_the_table(mission, browser):
    browser.get(mission.urls["scope"])
    wait_until(lambda: len(scope_counts(browser)) > 7, what="rows")
    group = browser.find_element("id", "group-filter")
    group.clear()
    group.send_keys(".*::node_status")
    browser.find_element("id", "filter-set").click()
    shown = wait_until(lambda: (c := scope_counts(browser)) and set(c) == {PREFIX + "node_status"} and c,
                     what="only node_status to be shown")
    assert list(shown) == [PREFIX + "node_status"]
    browser.find_element("id", "filter-clear").click()
    wait_until(lambda: len(scope_counts(browser)) > 7, what="every row back")

    browser.find_element("id", "pause").click()
    time.sleep(0.5)  # updates already on their way
    frozen = scope_counts(browser)
    time.sleep(2.0)  # node_status arrives at 20 Hz here
    assert scope_counts(browser) == frozen
    assert browser.find_element("id", "pause").text == "Play"
    browser.find_element("id", "pause").click()
    wait_until(lambda: scope_counts(browser)[PREFIX + "node_status"] > frozen[PREFIX + "node_status"],
             what="updates after Play")


def test_commander_refuses_out_of_range_then_sends_the_octagon(mission, browser):
    from selenium.webdriver.support.ui import Select

    browser.get(mission.urls["commander"])
    wait_until(lambda: browser.find_elements("css selector", '[data-path="desired_state"]'), what="the form")
    Select(browser.find_element("css selector", '[data-path="desired_state"]')).select_by_value("POLYGON")
    browser.find_element("css selector", '[data-path="polygon_sides"]').send_keys("8")
    radius = browser.find_element("css selector", '[data-path="polygon_radius"]')
    radius.send_keys("5000")
    browser.find_element("id", "send").click()
    error = browser.find_element("id", "command-error").text
    assert "polygon_radius" in error and "outside its DCCL bounds [100, 2000]" in error, error
    assert "invalid" in radius.get_attribute("class")
    assert browser.find_elements("css selector", "#sent-table tbody tr") == []  # nothing was sent

    before = len(command_effects(mission.record))
    radius.clear()
    radius.send_keys("400")
    browser.find_element("id", "send").click()
    state = wait_until(lambda: (cell := browser.find_elements("css selector", "#sent-table tbody tr td.state"))
                     and cell[0].text == "acknowledged" and cell[0], what="the ack in the page")
    acks = state.find_element("xpath", "following-sibling::td").text
    assert "POSTED_TO_MOOS" in acks and "DEPLOY_STATE=POLYGON" in acks

    def new_effect():
        mission.poll()
        effects = command_effects(mission.record)
        return effects[before:] if len(effects) > before else None

    (effect,) = wait_until(new_effect, what="the command's postings on the MOOSDB")
    assert [p.name for p in effect.posts] == ["POLYGON_UPDATES", "DEPLOY_STATE"]  # in that order
    assert effect.posts[0].value == "polygon=radial::x=0,y=0,radius=400,pts=8"
    assert effect.posts[1].value == "POLYGON"
    screenshot(browser, "commander")


def send_octagon(browser) -> None:
    """Fill the commander's form with POLYGON, 8 sides, radius 400, and Send."""
    from selenium.webdriver.support.ui import Select

    wait_until(lambda: browser.find_elements("css selector", '[data-path="desired_state"]'), what="the form")
    Select(browser.find_element("css selector", '[data-path="desired_state"]')).select_by_value("POLYGON")
    browser.find_element("css selector", '[data-path="polygon_sides"]').send_keys("8")
    browser.find_element("css selector", '[data-path="polygon_radius"]').send_keys("400")
    browser.find_element("id", "send").click()


def test_topside_commander_sends_the_octagon_over_the_satellite_link(mission, browser):
    """The course's way: the topside's page (its own broker) sends on intervehicle; the USV's modem acks."""
    from selenium.webdriver.support.ui import Select

    browser.get(mission.liaison_urls(process_name="topside.liaison")["commander"])
    wait_until(lambda: browser.find_elements("css selector", "#command-target option"), what="the targets")
    target = Select(browser.find_element("id", "command-target")).first_selected_option.text
    assert target == "goby3_course::usv_command/0 [intervehicle]"
    before = len(command_effects(mission.record))
    send_octagon(browser)
    state = wait_until(lambda: (cell := browser.find_elements("css selector", "#sent-table tbody tr td.state"))
                       and cell[0].text not in ("sending", "sent") and cell[0], timeout=60, what="the link's ack")
    acks = state.find_element("xpath", "following-sibling::td").text
    assert state.text == "acknowledged", acks
    assert acks.startswith("Ack: ") and "src: 2" in acks  # the USV's satellite modem

    def new_effect():
        mission.poll()
        effects = command_effects(mission.record)
        return effects[before:] if len(effects) > before else None

    (effect,) = wait_until(new_effect, what="the command's postings on the USV's MOOSDB")
    assert [p.name for p in effect.posts] == ["POLYGON_UPDATES", "DEPLOY_STATE"]
    assert effect.posts[0].value == "polygon=radial::x=0,y=0,radius=400,pts=8"
    assert effect.posts[1].value == "POLYGON"
    screenshot(browser, "topside_commander")


def drawn(browser, what: str):
    return browser.execute_script(f"return LiveMap.{what}")


def test_map_draws_the_vehicle_its_trail_and_the_helms_overlays(mission, browser):
    browser.get(mission.urls["map"])
    wait_until(lambda: "usv" in drawn(browser, "drawn.vehicles"), what="the vehicle drawn")
    assert drawn(browser, "vehicles.get('usv').data.type") == "USV"
    wait_until(lambda: drawn(browser, "vehicles.get('usv').points.length") > 3, what="a trail")
    assert len(drawn(browser, "overlays.waypoints")) > 50
    # the mode and the loiter polygon are the helm's own (DEPLOY_STATE, VIEW_POLYGON from its MOOSDB)
    wait_until(lambda: drawn(browser, "overlays.polygon_source") == "helm", what="the helm's VIEW_POLYGON")
    assert browser.find_element("id", "map-mode").text == "POLYGON (from the helm's DEPLOY_STATE)"
    assert len(drawn(browser, "drawn.polygon")) in (6, 8)
    # the vehicle's row says how long ago its last report arrived (a live vehicle: a few seconds at most)
    age = wait_until(lambda: browser.find_element("css selector", "#vehicle-table tbody tr td:nth-child(6)").text,
                     what="the last report's age")
    assert 0 <= int(age) < 30
    time.sleep(2)  # let the trail grow for the picture
    screenshot(browser, "map")


def helm_polygon(mission) -> list[tuple[float, float]] | None:
    """The vertices of the helm's last VIEW_POLYGON on the USV's MOOSDB."""
    mission.poll()
    views = mission.record.events_named("VIEW_POLYGON", source="moos")
    polygon = parse_polygon(views[-1].value) if views else None
    return [(round(x, 1), round(y, 1)) for x, y in polygon.vertices] if polygon else None


def test_a_polygon_drawn_on_the_map_is_acked_drawn_where_the_helm_has_it_and_changes_the_track(mission, browser):
    """POLYGON while already in POLYGON: the page draws the ring where the helm keeps it (its VIEW_POLYGON), not
    re-centred on the vehicle; the command goes through the commander's path (its ack) and the boat follows."""
    browser.get(mission.urls["map"])
    wait_until(lambda: drawn(browser, "overlays.polygon_source") == "helm" and drawn(browser, "command"),
               what="the map with the helm's polygon and the command tool")
    assert browser.find_element("id", "map-mode").text.startswith("POLYGON")  # already loitering
    sides = browser.find_element("id", "map-sides")
    sides.clear()
    sides.send_keys("6")
    radius = browser.find_element("id", "map-radius")
    radius.clear()
    radius.send_keys("700")
    browser.find_element("id", "map-send-polygon").click()
    cell = wait_until(lambda: (c := browser.find_element("css selector", "#vehicle-table tr[data-vehicle=usv] td:nth-child(8)"))
                      and "acknowledged" in c.text and c, what="the command's ack beside the USV")
    assert "polygon_radius: 700" in cell.text and "polygon_sides: 6" in cell.text

    def helm_has_the_new_ring():
        ring = helm_polygon(mission)
        return ring if ring and len(ring) == 6 and abs(Polygon(tuple(ring)).mean_radius - 700) < 1 else None

    ring = wait_until(helm_has_the_new_ring, what="the helm's VIEW_POLYGON of the new ring")
    page = wait_until(lambda: (p := drawn(browser, "drawn.polygon")) and len(p) == 6 and p, what="the new ring drawn")
    assert [tuple(p) for p in page] == ring  # the helm's own vertices, wherever the vehicle was
    assert drawn(browser, "overlays.polygon_source") == "helm"
    centre = Polygon(tuple(ring)).center

    def on_the_new_ring():
        x, y = drawn(browser, "drawn.vehicles")["usv"]
        return math.hypot(x - centre[0], y - centre[1]) > 550 and Polygon(tuple(ring)).distance((x, y)) < 60

    wait_until(on_the_new_ring, timeout=60, what="the USV out on the 700 m ring")
    screenshot(browser, "map_command")
