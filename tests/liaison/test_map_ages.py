"""The topside's map carries the age of each vehicle's last report (issue 25: a silent vehicle shows as stale)."""

from __future__ import annotations

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus
from launch.liaison import map_model
from launch.liaison.map_model import MapModel


class FakeClock:
    """The page's clock (sim seconds), moved by the test."""

    def __init__(self) -> None:
        self.t = 1000.0

    def __call__(self) -> float:
        return self.t


def _status(name: str, x: float) -> bytes:
    status = NodeStatus(name=name, time=1.0)
    status.local_fix.x, status.local_fix.y = x, 0.0
    status.global_fix.lat, status.global_fix.lon = 41.5, -70.6
    status.pose.heading, status.speed.over_ground = 90.0, 1.5
    return status.SerializeToString()


def test_each_vehicle_shows_how_long_ago_its_last_report_arrived(monkeypatch) -> None:
    clock = FakeClock()
    model = MapModel([], [], clock_now=clock)
    model.ingest_node_status("auv0_nav", _status("AUV_0", 0.0))
    model.ingest_node_status("usv_nav", _status("USV", 5.0))
    first = model.tick()
    assert first is not None and first["ages"] == {"AUV_0": 0, "USV": 0}

    clock.t += 30.0  # the USV keeps reporting, AUV_0 has gone silent
    model.ingest_node_status("usv_nav", _status("USV", 10.0))
    monkeypatch.setattr(map_model, "HEALTH_RESEND_S", 0.0)  # the ages are due at once
    update = model.tick()
    assert update is not None and update["ages"] == {"AUV_0": 30, "USV": 0}
    assert model.snapshot()["ages"] == {"AUV_0": 30, "USV": 0}

    clock.t += 12.0  # nothing new at all: the ages still go out, growing
    update = model.tick()
    assert update is not None and update["vehicles"] == [] and update["ages"] == {"AUV_0": 42, "USV": 12}
