"""The managers' shared options and their start-up checks (no links needed)."""

from __future__ import annotations

import logging
import subprocess
import sys

from gateway.goby.portal.testing import broker_process
from translators.trail import groups
from translators.trail.nav_links import link_cfg, nav_publisher, nav_subscriber, received_nav_group
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport


def test_link_cfg_is_the_course_subscriber_config():
    cfg = link_cfg(258, broadcast=True, ack_required=False, max_queue=1, newest_first=True)
    assert list(cfg.intervehicle.publisher_id) == [258] and cfg.intervehicle.broadcast
    buffer = cfg.intervehicle.buffer
    assert (buffer.ack_required, buffer.max_queue, buffer.newest_first) == (False, 1, True)
    acked = link_cfg(2, ack_required=True, max_queue=10)
    assert not acked.intervehicle.HasField("broadcast") and not acked.intervehicle.buffer.HasField("newest_first")
    assert (acked.intervehicle.buffer.ack_required, acked.intervehicle.buffer.max_queue) == (True, 10)


def test_nav_options_write_and_read_the_group_in_type():
    publisher, subscriber = nav_publisher(), nav_subscriber(link_cfg(2), republish=False)
    nav = NavigationReport(vehicle=3)
    publisher.set_group(nav, groups.auv_nav)
    assert nav.type == NavigationReport.AUV and subscriber.group(nav) == groups.auv_nav
    assert not subscriber.republish and nav_subscriber(link_cfg(2)).republish


def test_a_report_of_no_navigation_group_is_logged_and_matches_nothing(caplog):
    with caplog.at_level(logging.ERROR):
        group = received_nav_group(NavigationReport(vehicle=9, type=NavigationReport.TOPSIDE))
    assert group not in (groups.usv_nav, groups.auv_nav)
    assert "vehicle 9" in caplog.text and "Unsupported VehicleClass TOPSIDE" in caplog.text


def test_a_manager_without_geodesy_refuses_to_start_in_one_line(tmp_path):
    config = tmp_path / "auv_manager.pb.cfg"
    config.write_text("usv_modem_id: 258\nvehicle_id: 2\n")
    with broker_process(tmp_path, platform="nogeo") as broker:
        result = subprocess.run([sys.executable, "-m", "translators.apps.auv_manager", str(config)],
                                env=broker.env(), capture_output=True, text=True, timeout=60)
    assert result.returncode == 1
    assert "auv-manager: no lat_origin and lon_origin defined" in result.stderr
    assert "Traceback" not in result.stderr
