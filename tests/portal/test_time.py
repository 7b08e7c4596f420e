"""The warped clock and conversions, against the worked values of spec §5 and Goby's time3 test (§8.2)."""

from __future__ import annotations

import datetime as dt
import time

import pytest

from gateway.goby.portal.timeutil import (
    NOT_A_DATE_TIME,
    SystemClock,
    datetime_to_micro,
    duration_micro_to_si,
    duration_si_to_micro,
    duration_to_whole_seconds,
    file_str,
    micro_to_datetime,
    micro_to_si,
    si_to_micro,
    start_of_year_micro,
    time_str,
)

TEST_MICRO = 1313523417523456  # 2011-08-16 19:36:57.523456 UTC


def test_point_in_time_conversions() -> None:
    when = dt.datetime(2011, 8, 16, 19, 36, 57, 523456, tzinfo=dt.UTC)
    assert datetime_to_micro(when) == TEST_MICRO
    assert micro_to_si(TEST_MICRO) == pytest.approx(1313523417.523456, abs=1e-6)
    assert si_to_micro(1313523417.523456) == TEST_MICRO
    assert micro_to_datetime(TEST_MICRO) == when
    assert time_str(TEST_MICRO) == "2011-Aug-16 19:36:57.523456"
    assert file_str(TEST_MICRO) == "20110816T193658"
    assert micro_to_datetime(NOT_A_DATE_TIME) is None
    assert datetime_to_micro(None) == NOT_A_DATE_TIME


def test_duration_conversions() -> None:
    assert duration_to_whole_seconds(3000012300) == 3000
    assert duration_micro_to_si(3000012300) == pytest.approx(3000.0123)
    assert duration_si_to_micro(3000.0123) == 3000012300
    assert duration_to_whole_seconds(-1_500_000) == -1  # truncation toward zero


def test_default_reference_is_start_of_current_utc_year() -> None:
    clock = SystemClock()
    year = dt.datetime.now(dt.UTC).year
    assert clock.reference_micro == datetime_to_micro(dt.datetime(year, 1, 1, tzinfo=dt.UTC))
    assert start_of_year_micro(TEST_MICRO) == datetime_to_micro(dt.datetime(2011, 1, 1, tzinfo=dt.UTC))


def test_warp_worked_values() -> None:
    clock = SystemClock(use_sim_time=True, warp_factor=10, reference_micro=1_000_000)
    assert clock.warp(1_000_000 + 5) == 1_000_000 + 50
    assert clock.unwarp(1_000_000 + 55) == 1_000_000 + 5  # truncating division
    assert clock.unwarp(1_000_000 - 55) == 1_000_000 - 5  # toward zero, not floor
    now = time.time_ns() // 1000
    assert clock.unwarp(clock.warp(now)) == now
    warped = clock.warp(now)
    assert clock.warp(clock.unwarp(warped)) == warped


def test_warped_now_runs_ahead_and_moos_style_reference() -> None:
    goby_style = SystemClock(use_sim_time=True, warp_factor=10)
    real = time.time()
    assert goby_style.now() > real
    moos_style = SystemClock(use_sim_time=True, warp_factor=10, reference_micro=0)
    assert abs(moos_style.now() / 10 - time.time()) < 1.0
    assert moos_style.effective_warp == 10


def test_sim_time_off_means_real_time() -> None:
    clock = SystemClock(use_sim_time=False, warp_factor=10)
    assert clock.effective_warp == 1
    assert abs(clock.now() - time.time()) < 0.5
    with pytest.raises(ValueError):
        SystemClock(use_sim_time=True, warp_factor=0)
