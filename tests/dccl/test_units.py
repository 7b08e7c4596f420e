"""DCCL units (gateway/goby/dccl/units.py): the course's HealthStatus.timestamp and NavigationReport fields set with
quantities in other units, through our DCCL codec and back; wrong dimensions refused; the lecture's "Time in Goby"
publisher/subscriber pair as real processes over a real broker."""

from __future__ import annotations

import datetime as dt
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

from gateway.goby.dccl import Codec, DcclError
from gateway.goby.dccl.units import (
    DimensionError,
    UnitsError,
    field_units,
    now,
    set_with_units,
    to_datetime,
    to_micro,
    ureg,
    with_units,
)
from gateway.goby.portal.testing import app_process, broker_process
from gateway.goby.portal.timeutil import SystemClock
from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_options
from translators.trail.protobuf.health_status_pb2 import HealthStatus
from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport

ROOT = Path(__file__).resolve().parents[2]
NOW_S = 1_700_000_000.0  # the receiver's clock for time fields (decoded within +-12 h of it)


def round_trip(msg: Any) -> Any:
    codec = Codec(clock=lambda: NOW_S)
    codec.load(type(msg))
    return codec.decode(codec.encode(msg))


def test_units_of_the_course_fields() -> None:
    expected = {"time": "second", "x": "meter", "y": "meter", "z": "meter", "speed_over_ground": "meter / second",
                "heading": "degree"}
    for name, unit in expected.items():
        assert str(field_units(NavigationReport, name).unit) == unit, name
    timestamp = field_units(HealthStatus, "timestamp")
    assert str(timestamp.unit) == "microsecond"
    assert timestamp.integer


def test_health_status_timestamp_in_other_units_round_trips() -> None:
    # 1.7e9 s + 1 h 4.5 s, given in minutes: stored in microseconds, sent in whole seconds of the day (dccl.time2)
    when = (NOW_S + 3600) * ureg.second + 4.5 * ureg.second
    status = HealthStatus(state=HealthStatus.GOOD)
    set_with_units(status, "timestamp", when.to("minute"))
    assert status.timestamp == 1_700_003_604_500_000
    decoded = round_trip(status)
    got = with_units(decoded, "timestamp")
    assert str(got.units) == "microsecond"
    assert abs((got - when).to("second").magnitude) <= 1.0  # the field's precision: one second
    assert to_datetime(got) == dt.datetime(2023, 11, 14, 23, 13, 25, tzinfo=dt.UTC)  # 4.5 s rounded up


def test_navigation_report_fields_in_other_units_round_trip() -> None:
    report = NavigationReport(vehicle=3)
    given = {
        "time": (NOW_S / 60 + 10) * ureg.minute,
        "x": -1234.5 * ureg.foot,
        "y": 2.5 * ureg.kilometer,
        "z": -30 * ureg.fathom,
        "speed_over_ground": 7.2 * ureg.kilometer / ureg.hour,
        "heading": 1.5 * ureg.radian,
    }
    for name, quantity in given.items():
        set_with_units(report, name, quantity)
    assert report.speed_over_ground == pytest.approx(2.0)
    assert report.heading == pytest.approx(85.943669, abs=1e-6)
    decoded = round_trip(report)
    # each field's precision: time 1 s, x/y/speed 0.1, z and heading 1 (in the field's units)
    tolerance = {"time": 1 * ureg.second, "x": 0.05 * ureg.meter, "y": 0.05 * ureg.meter, "z": 0.5 * ureg.meter,
                 "speed_over_ground": 0.05 * ureg.meter / ureg.second, "heading": 0.5 * ureg.degree}
    for name, quantity in given.items():
        got = with_units(decoded, name)
        assert abs(got - quantity) <= tolerance[name] + 1e-9 * abs(quantity), (name, got, quantity)
    assert with_units(decoded, "x").to("foot").magnitude == pytest.approx(-1234.5, abs=0.05 / 0.3048)


def test_wrong_dimension_is_refused_naming_the_field_and_both_dimensions() -> None:
    report = NavigationReport()
    with pytest.raises(DimensionError) as caught:
        set_with_units(report, "x", 3 * ureg.second)
    text = str(caught.value)
    assert "NavigationReport.x" in text and "[length]" in text and "[time]" in text
    assert not report.HasField("x")
    with pytest.raises(DimensionError, match=r"NavigationReport.speed_over_ground .*\[length\] / \[time\].*\[length\]"):
        set_with_units(report, "speed_over_ground", 4 * ureg.knot * ureg.hour)
    with pytest.raises(DimensionError, match=r"HealthStatus.timestamp .*\[time\].*\[length\]"):
        set_with_units(HealthStatus(), "timestamp", 1 * ureg.meter)
    assert isinstance(caught.value, DcclError)


def test_fields_without_units_and_values_that_do_not_fit_are_refused() -> None:
    with pytest.raises(UnitsError, match=r"HealthStatus.state has no DCCL units"):
        set_with_units(HealthStatus(), "state", 1 * ureg.second)
    with pytest.raises(UnitsError, match=r"NavigationReport.vehicle has no DCCL units"):
        with_units(NavigationReport(vehicle=1), "vehicle")
    with pytest.raises(UnitsError, match=r"NavigationReport has no field 'speed'"):
        with_units(NavigationReport(), "speed")
    with pytest.raises(UnitsError, match=r"takes a quantity with units \(meter\), not 5"):
        set_with_units(NavigationReport(), "x", 5)
    with pytest.raises(UnitsError, match=r"HealthStatus.timestamp cannot hold -1 second"):
        set_with_units(HealthStatus(), "timestamp", -1 * ureg.second)


def test_now_is_microtime_on_the_warped_clock() -> None:
    real = SystemClock()
    warped = SystemClock(use_sim_time=True, warp_factor=10, reference_micro=0)
    before = real.now_micro()
    stamp = now(real)
    assert isinstance(stamp.magnitude, int) and str(stamp.units) == "microsecond"
    assert before <= stamp.magnitude <= real.now_micro()
    # warp 10 from the epoch: about ten times the real time since 1970
    assert now(warped).to("second").magnitude == pytest.approx(10 * before / 1e6, rel=1e-6)
    assert to_micro(2.5 * ureg.second) == 2_500_000


def test_pint_is_not_imported_for_messages_without_units() -> None:
    code = ("import sys\nfrom gateway.goby.dccl import Codec\nimport gateway.goby.dccl.units\n"
            "from translators.trail.protobuf.nav_dccl_pb2 import NavigationReport\n"
            "c = Codec(); c.load(NavigationReport); c.encode(NavigationReport(vehicle=1, time=0, x=0, y=0, z=0,"
            " speed_over_ground=0, heading=0))\nprint('pint' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "False"


def test_publisher_subscriber_pair_prints_a_date_and_a_latency(tmp_path: Path) -> None:
    with broker_process(tmp_path) as broker:
        env = broker.env()
        subscriber = app_process([sys.executable, "-m", "translators.trail.examples.health_subscriber"],
                                 tmp_path / "subscriber.log", env=env, cwd=ROOT)
        publisher = app_process([sys.executable, "-m", "translators.trail.examples.health_publisher"],
                                tmp_path / "publisher.log", env=env, cwd=ROOT)
        try:
            # the second message: the first one waits for the broker's hold release
            assert subscriber.wait_for_output(re.compile(r"(?s)Latency.*Latency \(microsec\): \d+"), 60), \
                subscriber.stderr_text() + publisher.stderr_text()
        finally:
            publisher.stop()
            subscriber.stop()
    lines = subscriber.lines()
    dates = [m for line in lines if (m := re.fullmatch(r"Timestamp as date: (\d{4}-\w{3}-\d{2} [\d:.]+)", line))]
    latencies = [int(m.group(1)) for line in lines if (m := re.fullmatch(r"Latency \(microsec\): (-?\d+)", line))]
    assert len(dates) >= 2 and len(latencies) >= 2, lines
    printed = dt.datetime.strptime(dates[-1].group(1), "%Y-%b-%d %H:%M:%S.%f").replace(tzinfo=dt.UTC)
    assert abs((dt.datetime.now(dt.UTC) - printed).total_seconds()) < 60
    assert 0 <= latencies[-1] < 5_000_000


def units_type(units: dict[str, Any], field_type: str = "double", unit_system: str | None = None) -> Any:
    """A message ``U`` with one field ``v`` carrying ``(dccl.field).units = units``."""
    fdp = descriptor_pb2.FieldDescriptorProto
    file_proto = descriptor_pb2.FileDescriptorProto(name="units_test.proto", package="units_test", syntax="proto2")
    message = file_proto.message_type.add(name="U")
    if unit_system is not None:
        message.options.Extensions[dccl_options.msg].unit_system = unit_system
    field = message.field.add(name="v", number=1, label=fdp.LABEL_OPTIONAL,
                              type={"double": fdp.TYPE_DOUBLE, "int32": fdp.TYPE_INT32}[field_type])
    for key, value in units.items():
        setattr(field.options.Extensions[dccl_options.field].units, key, value)
    pool = descriptor_pool.DescriptorPool()
    pool.Add(file_proto)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName("units_test.U"))


@pytest.mark.parametrize(("units", "unit_system", "expected"), [
    ({"base_dimensions": "LT^-1"}, "si", "meter / second"),
    ({"base_dimensions": "L T^-2", "system": "cgs"}, None, "centimeter / second ** 2"),
    ({"base_dimensions": "M", "system": "cgs", "prefix": "kilo"}, None, "kilogram"),
    ({"derived_dimensions": "length/time", "prefix": "kilo"}, "si", "kilometer / second"),
    ({"derived_dimensions": "velocity"}, "si", "meter / second"),
    ({"derived_dimensions": "pressure"}, "si", "kilogram / meter / second ** 2"),
    ({"derived_dimensions": "plane_angle", "system": "angle::degree"}, "si", "degree"),
    ({"derived_dimensions": "temperature", "system": "temperature::celsius"}, None, "degree_Celsius"),
    ({"derived_dimensions": "temperature", "system": "celsius", "relative_temperature": True}, None,
     "delta_degree_Celsius"),
    ({"unit": "imperial::foot"}, None, "foot"),
    ({"unit": "metric::knot"}, None, "knot"),
    ({"unit": "metric::nautical_mile", "prefix": "milli"}, None, "millinautical_mile"),
])
def test_unit_of_each_kind_of_definition(units: dict[str, Any], unit_system: str | None, expected: str) -> None:
    assert str(field_units(units_type(units, unit_system=unit_system), "v").unit) == expected


def test_celsius_field_converts_absolute_temperatures() -> None:
    msg = units_type({"derived_dimensions": "temperature"}, unit_system="temperature::celsius")()
    set_with_units(msg, "v", ureg.Quantity(300.15, "kelvin"))
    assert msg.v == pytest.approx(27.0)
    assert with_units(msg, "v").to("degF").magnitude == pytest.approx(80.6)


@pytest.mark.parametrize(("units", "unit_system", "error"), [
    ({"base_dimensions": "L"}, None, "must set units.system or its message"),
    ({"base_dimensions": "LQ"}, "si", "cannot parse base_dimensions 'LQ' at 'Q'"),
    ({"derived_dimensions": "length/banana"}, "si", "unknown derived dimension 'banana'"),
    ({"derived_dimensions": "length", "system": "imperial"}, None, "unit system 'imperial' is not supported"),
    ({"derived_dimensions": "length", "system": "angle::degree"}, None, "'angle::degree' has no unit of length"),
    ({"derived_dimensions": "length", "prefix": "mucho"}, "si", "invalid SI prefix 'mucho'"),
    ({"derived_dimensions": "length", "base_dimensions": "L"}, "si", "exactly one of base_dimensions"),
    ({"unit": "imperial::furlongs_per_week"}, None, "unknown base unit"),
])
def test_bad_units_definitions_are_refused(units: dict[str, Any], unit_system: str | None, error: str) -> None:
    with pytest.raises(UnitsError, match=re.escape(error)):
        field_units(units_type(units, unit_system=unit_system), "v")


def test_integer_fields_take_the_nearest_integer() -> None:
    msg = units_type({"base_dimensions": "L", "prefix": "milli"}, field_type="int32", unit_system="si")()
    set_with_units(msg, "v", 1.23456 * ureg.meter)
    assert msg.v == 1235
    set_with_units(msg, "v", 2 * ureg.inch)
    assert msg.v == 51  # 50.8 mm
