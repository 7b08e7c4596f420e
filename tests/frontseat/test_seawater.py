"""UNESCO 1983 seawater formulas against their published check values, and compute_missing on a CTDSample."""

from __future__ import annotations

import math

import pytest

from frontseat import seawater
from frontseat.driver import FrontSeatDriver
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from frontseat.protobuf import frontseat_data_pb2 as data_pb


def test_check_values() -> None:
    assert seawater.salinity_from_ratio(1.888091, 40, 10000) == pytest.approx(40.0000, abs=5e-5)  # UNESCO 44
    assert seawater.salinity(seawater.STANDARD_CONDUCTIVITY, 15, 0) == pytest.approx(35.0, abs=1e-3)
    assert seawater.salinity(1e-6, 10, 0) == 0.0
    # Goby's seawater test vectors (spec §8)
    assert seawater.depth(10000, 30) == pytest.approx(9712.653, abs=1e-3)
    assert seawater.depth(500, 0) == pytest.approx(496.65, abs=1e-2)
    assert seawater.depth(5000, 60) == pytest.approx(4895.60, abs=1e-2)
    assert seawater.depth(9000, 90) == pytest.approx(8724.85, abs=1e-2)
    assert seawater.mackenzie_sound_speed(25, 35, 1000) == pytest.approx(1550.744, abs=1e-3)
    with pytest.raises(ValueError, match="Mackenzie"):
        seawater.mackenzie_sound_speed(31, 35, 1000)
    # EOS-80 (UNESCO 38): sigma 62.53817 at (35, 25 C, 1000 bar); 59.82037 at (40, 40 C, 10000 dbar)
    assert seawater.density(35, 25, 10000) == pytest.approx(1062.53817, abs=1e-5)
    assert seawater.density(40, 40, 10000) == pytest.approx(1059.82037, abs=1e-5)


class _Driver(FrontSeatDriver):
    """Minimal concrete driver (test double): only the base class's compute_missing is under test."""

    def send_command_to_frontseat(self, command) -> None: ...
    def send_data_to_frontseat(self, data) -> None: ...
    def send_raw_to_frontseat(self, raw) -> None: ...
    def frontseat_state(self) -> int:
        return 0

    def frontseat_providing_data(self) -> bool:
        return False

    def loop(self) -> None: ...


class _Clock:
    def now(self) -> float:
        return 0.0


def test_compute_missing_ctd_fills_secondary_quantities() -> None:
    driver = _Driver(config_pb.Config(), clock=_Clock())
    ctd = data_pb.CTDSample(time=1, conductivity=4.2914, temperature=15, pressure=1000e4)  # 1000 dbar
    ctd.global_fix.lat, ctd.global_fix.lon = 30, -70
    driver.compute_missing(ctd)
    s = seawater.salinity(4.2914, 15, 1000)
    assert ctd.salinity == pytest.approx(s) and 34 < s < 36
    assert ctd.global_fix.depth == pytest.approx(seawater.depth(1000, 30))
    assert ctd.sound_speed == pytest.approx(seawater.mackenzie_sound_speed(15, s, ctd.global_fix.depth))
    assert ctd.density == pytest.approx(seawater.density(s, 15, 1000))
    assert ctd.salinity_algorithm == data_pb.CTDSample.UNESCO_44_PREKIN_AND_LEWIS_1980
    assert ctd.sound_speed_algorithm == data_pb.CTDSample.MACKENZIE_1981
    assert ctd.density_algorithm == data_pb.CTDSample.UNESCO_38_MILLERO_AND_POISSON_1981

    warm = data_pb.CTDSample(time=1, temperature=35, pressure=0, salinity=35)  # outside Mackenzie's range
    warm.global_fix.lat, warm.global_fix.lon = 0, 0
    driver.compute_missing(warm)
    assert math.isnan(warm.sound_speed) and warm.sound_speed_algorithm == data_pb.CTDSample.MACKENZIE_1981
    assert warm.salinity_algorithm == data_pb.CTDSample.SAL_ALGORITHM_UNKNOWN  # salinity was given
