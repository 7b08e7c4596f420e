"""The fleet on the maps of the trail mission (topside, USV and 2 AUVs at warp 10), in real headless Chromium: the
topside's map lists every vehicle from the NodeStatus topside-manager makes of the satellite link's reports, each
with its report's age; the USV's map shows the AUVs from their acoustic reports (the NavigationReports usv-manager
forwards); a polygon drawn on the topside's map is acked by the satellite link.  Set LIAISON_SCREENSHOT_DIR to keep the pictures (docs/liaison_map.png is the USV's)."""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import pytest

from launch.liaison.testing import browser_skip_reason, chromium
from launch.process_group import child_environment
from launch.trail.mission import TrailMission, with_free_ports
from launch.trail.settings import TrailSettings, Vehicle

N_AUVS = 2
WARP = 10
NEEDED = ("auv-manager", "topside-manager", "usv-manager")
SKIP = browser_skip_reason() or next((f"{p} is not installed" for p in NEEDED
                                      if shutil.which(p, path=child_environment()["PATH"]) is None), None)
pytestmark = pytest.mark.skipif(SKIP is not None, reason=str(SKIP))
FLEET = {"USV", "AUV_0", "AUV_1"}


def rows(driver) -> dict[str, list[str]]:
    """The map's vehicle table: name -> its cells."""
    return driver.execute_script(
        "return Object.fromEntries([...document.querySelectorAll('#vehicle-table tbody tr')]"
        ".map(r => [r.dataset.vehicle, [...r.children].map(c => c.textContent)]))")


def test_the_topside_and_usv_maps_show_the_fleet(tmp_path):
    settings = with_free_ports(TrailSettings(run_dir=tmp_path, warp=WARP, socket_dir=tmp_path), N_AUVS,
                               prefer_course=False)
    mission = TrailMission(settings, N_AUVS, report=lambda line: None, launch_delay_s=0.5)
    url = {name: f"http://127.0.0.1:{Vehicle(name, N_AUVS).liaison_port(settings)}/?_=/map"
           for name in ("topside", "usv")}
    shots = os.environ.get("LIAISON_SCREENSHOT_DIR")
    try:
        with chromium() as driver:
            mission.start()
            assert mission.wait_for_command(timeout_s=120) is not None
            driver.get(url["topside"])
            mission.run(300, until=lambda: FLEET <= set(rows(driver)))
            topside = rows(driver)
            assert FLEET <= set(topside), topside
            for name in FLEET:  # each report's age, in sim seconds: the satellite link's slots are 5 s
                assert 0 <= int(topside[name][5]) < 120, topside[name]
            assert driver.execute_script("return LiveMap.vehicles.get('AUV_0').data.type") == "AUV"
            # a polygon drawn on the topside's map goes over the satellite link, acked by the USV's modem
            for field, value in (("map-sides", "6"), ("map-radius", "150")):
                driver.find_element("id", field).clear()
                driver.find_element("id", field).send_keys(value)
            driver.find_element("id", "map-send-polygon").click()
            mission.run(120, until=lambda: "acknowledged" in rows(driver)["USV"][7])
            assert "acknowledged" in rows(driver)["USV"][7], rows(driver)["USV"]
            assert "polygon_radius: 150" in rows(driver)["USV"][7]
            if shots:
                Path(shots).mkdir(parents=True, exist_ok=True)
                driver.save_screenshot(str(Path(shots) / "liaison_topside_map.png"))

            driver.get(url["usv"])
            mission.run(300, until=lambda: {"AUV_0", "AUV_1"} <= set(rows(driver)))
            usv = rows(driver)
            assert {"AUV_0", "AUV_1"} <= set(usv), usv  # from the acoustic reports
            assert any(cells[0].endswith("(USV)") for cells in usv.values()), usv  # and its own NodeStatus
            if shots:
                end = time.monotonic() + 25.0  # trails for the picture
                mission.run(None, until=lambda: time.monotonic() > end)
                driver.save_screenshot(str(Path(shots) / "liaison_map.png"))
    finally:
        result = mission.stop()
    assert all(o.clean for o in result.outcomes), result.outcomes
    assert not result.log_errors, result.log_errors[:10]
