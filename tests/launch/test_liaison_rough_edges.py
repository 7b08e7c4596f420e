"""The liaison pages' rough edges of issue 29, in a real headless Chromium on a real broker and goby-liaison.

- the scope's filters match the whole name (as Goby's liaison): the page says so, and when a filter leaves no
  row it says why and offers the ``.*x.*`` form;
- the commander says when DCCL's precision changes a typed value (405 goes as 410), shows the typed comment in
  the sent log, and gives the link's latency (microseconds on the wire) in ms or s.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

import pytest

from gateway.goby.dccl.arith import quantize_float, quantize_int
from gateway.goby.portal.testing import PortalClient
from launch.liaison.portal_side import LiaisonApp
from launch.liaison.testing import browser_skip_reason, chromium
from tests.liaison.test_rough_edges import topside  # noqa: F401 - the fixture: a satellite link, no USV
from tests.liaison.test_server import liaison  # noqa: F401 - the fixture: a liaison and a test client
from tests.markers import needs_loopback_multicast
from translators.usv import groups as usv_groups
from translators.usv.protobuf.command_ack_pb2 import USVCommandAck
from translators.usv.protobuf.command_dccl_pb2 import USVCommand
from util.process import wait_until

SKIP = browser_skip_reason()
pytestmark = pytest.mark.skipif(SKIP is not None, reason=str(SKIP))

STATE_GROUPS = ["goby3_course::usv_deploy_state", "goby3_course::auv0_deploy_state"]


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with chromium() as driver:
        yield driver


def scope_groups(driver: Any) -> set[str]:
    return set(driver.execute_script(
        "return [...document.querySelectorAll('#scope-table tbody tr.row')].map(r => r.children[0].textContent)"))


def set_group_filter(driver: Any, expression: str) -> None:
    group = driver.find_element("id", "group-filter")
    group.clear()
    group.send_keys(expression)
    driver.find_element("id", "filter-set").click()


def test_a_filter_that_matches_no_whole_name_says_so_and_offers_the_containing_form(
        liaison: tuple[LiaisonApp, PortalClient], browser: Any) -> None:  # noqa: F811
    app, client = liaison
    for group in STATE_GROUPS:
        client.publish(group, "POLYGON")
    client.publish("goby3_course::usv_nav", "x=1")
    client.poll(0.01)
    browser.get(f"http://127.0.0.1:{app.web.port}/?_=/scope")
    wait_until(lambda: set(STATE_GROUPS) <= scope_groups(browser), what="the published groups in the scope")
    hint = browser.find_element("id", "filter-hint").text
    assert "whole name" in hint and ".*state.*" in hint, hint
    assert ".*state.*" in browser.find_element("id", "group-filter").get_attribute("title")
    assert not browser.find_element("id", "filter-empty").is_displayed()  # rows shown: nothing to explain

    set_group_filter(browser, "state")
    empty = wait_until(lambda: (line := browser.find_element("id", "filter-empty")).is_displayed() and line,
                       what="the no-match line")
    assert scope_groups(browser) == set()
    assert 'group "state"' in empty.text and "as a whole" in empty.text and '".*state.*"' in empty.text, empty.text

    browser.find_element("id", "filter-containing").click()
    wait_until(lambda: scope_groups(browser) == set(STATE_GROUPS), what="the groups containing state")
    assert browser.find_element("id", "group-filter").get_attribute("value") == ".*state.*"
    assert not browser.find_element("id", "filter-empty").is_displayed()


def fill_polygon(driver: Any, sides: str, radius: str) -> None:
    from selenium.webdriver.support.ui import Select

    wait_until(lambda: driver.find_elements("css selector", '[data-path="desired_state"]'), what="the form")
    Select(driver.find_element("css selector", '[data-path="desired_state"]')).select_by_value("POLYGON")
    driver.find_element("css selector", '[data-path="polygon_sides"]').send_keys(sides)
    driver.find_element("css selector", '[data-path="polygon_radius"]').send_keys(radius)


def test_a_rounded_value_is_said_and_the_comment_is_logged(liaison: tuple[LiaisonApp, PortalClient],  # noqa: F811
                                                           browser: Any) -> None:
    app, client = liaison
    commands = client.collect(usv_groups.shore_usv_command, USVCommand)
    client.wait_subscribed()
    browser.get(f"http://127.0.0.1:{app.web.port}/?_=/commander")
    fill_polygon(browser, "8", "405")
    note = browser.find_element("css selector", '[data-rounding="polygon_radius"]').text
    assert note == "— polygon_radius: 405 is sent as 410 (DCCL precision: steps of 10)", note
    assert browser.find_element("css selector", '[data-rounding="polygon_sides"]').text == ""  # an integer step 1
    browser.find_element("id", "command-comment").send_keys("first loiter, radius 405")
    browser.find_element("id", "send").click()

    assert client.poll_until(lambda: bool(commands), 10)
    assert commands[0].polygon_radius == 410  # what the note said is what went out
    status = wait_until(lambda: (text := browser.find_element("id", "send-status").text).startswith("sent #")
                        and text, what="the sent status")
    assert "polygon_radius: 405 is sent as 410" in status, status
    row = wait_until(lambda: browser.find_elements("css selector", "#sent-table tbody tr"), what="the sent log")[0]
    cells = row.find_elements("tag name", "td")
    assert "polygon_radius: 410" in cells[4].text and "405 is sent as 410" in cells[4].text, cells[4].text
    assert cells[7].text == "first loiter, radius 405"
    headers = [th.text for th in browser.find_elements("css selector", "#sent-table thead th")]
    assert headers[-1] == "Comment" and len(headers) == len(cells), headers

    client.publish(usv_groups.usv_command_ack, USVCommandAck(
        stage=USVCommandAck.POSTED_TO_MOOS, command_time=commands[0].time, responder="test"))
    wait_until(lambda: row.find_element("css selector", "td.state").text == "acknowledged", what="the ack")
    assert row.find_elements("tag name", "td")[7].text == "first loiter, radius 405"  # kept through updates


def test_the_page_rounds_as_the_dccl_codec_does(liaison: tuple[LiaisonApp, PortalClient],  # noqa: F811
                                                browser: Any) -> None:
    app, _client = liaison
    browser.get(f"http://127.0.0.1:{app.web.port}/?_=/commander")
    wait_until(lambda: browser.find_elements("css selector", '[data-path="desired_state"]'), what="the form")
    integers = [(v, 10) for v in (-416, -415, -406, -405, -404, 0, 4, 5, 404, 405, 406, 1995)]
    reals = [(v, 0.1) for v in (-0.25, -0.05, 0.04, 0.05, 0.15, 0.25, 12.349, 12.35)]
    reals += [(v, 100.0) for v in (-150.0, -149.9, 49.9, 50.0, 149.0, 150.0)]
    cases = [(v, s, True) for v, s in integers] + [(v, s, False) for v, s in reals]
    page = browser.execute_script("return arguments[0].map(([v, s, i]) => dcclQuantize(v, s, i));", cases)
    codec = [quantize_int(v, s) for v, s in integers] + [quantize_float(v, s) for v, s in reals]
    assert page == pytest.approx(codec, abs=1e-9), list(zip(cases, page, codec, strict=True))


@needs_loopback_multicast
def test_the_link_latency_has_its_unit(topside: LiaisonApp, browser: Any) -> None:  # noqa: F811
    from selenium.webdriver.support.ui import Select

    browser.get(f"http://127.0.0.1:{topside.web.port}/?_=/commander")
    wait_until(lambda: browser.find_elements("css selector", '[data-path="desired_state"]'), what="the form")
    Select(browser.find_element("css selector", '[data-path="desired_state"]')).select_by_value("WAYPOINTS")
    browser.find_element("id", "send").click()
    state = wait_until(lambda: (cell := browser.find_elements("css selector", "#sent-table tbody tr td.state"))
                       and cell[0].text == "expired" and cell[0], what="the expiry in the page", timeout=30)
    text = state.find_element("xpath", "following-sibling::td").text
    assert text.startswith("Expire: ") and "EXPIRED_NO_SUBSCRIBERS" in text, text
    assert re.search(r"\blatency: \d+(\.\d+)? (ms|s)\b", text), text  # microseconds on the wire, ms/s on the page
    assert not re.search(r"\blatency: -?\d+(?![\d.]* m?s)", text), text
