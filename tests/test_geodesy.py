"""UTM local grid against the reference values of ivp_helm.md §7.3 (origin Forest Lake, zone 19T)."""

from __future__ import annotations

import pytest

from tests.geodesy_reference import ORIGIN, REFERENCE
from util.geodesy import UTMGeodesy, utm_zone

FOREST_LAKE = ORIGIN


@pytest.fixture(scope="module")
def geodesy() -> UTMGeodesy:
    return UTMGeodesy(*FOREST_LAKE)


def test_origin_projects_to_reference_utm(geodesy: UTMGeodesy) -> None:
    assert geodesy.zone == 19
    east0, north0 = geodesy.origin_utm
    assert east0 == pytest.approx(393023.475, abs=0.01)
    assert north0 == pytest.approx(4853329.70, abs=0.01)


@pytest.mark.parametrize(("local", "geo"), REFERENCE)
def test_local_to_geo_matches_reference(geodesy: UTMGeodesy, local, geo) -> None:
    lat, lon = geodesy.to_geo(*local)
    assert lat == pytest.approx(geo[0], abs=1e-8)
    assert lon == pytest.approx(geo[1], abs=1e-8)


@pytest.mark.parametrize(("local", "geo"), REFERENCE)
def test_geo_to_local_matches_reference(geodesy: UTMGeodesy, local, geo) -> None:
    x, y = geodesy.to_local(*geo)
    # 1e-8 degrees is about 1 mm; the reference is given to 8 decimals.
    assert x == pytest.approx(local[0], abs=0.002)
    assert y == pytest.approx(local[1], abs=0.002)


def test_origin_is_local_zero(geodesy: UTMGeodesy) -> None:
    assert geodesy.to_local(*FOREST_LAKE) == pytest.approx((0.0, 0.0), abs=1e-6)


def test_zone_is_fixed_by_origin_across_a_boundary() -> None:
    # Origin just west of the 18/19 boundary (-72 deg): a point 5 km east is in zone 19 but stays on zone 18's grid.
    geodesy = UTMGeodesy(43.0, -72.01)
    assert geodesy.zone == 18
    lat, lon = geodesy.to_geo(5000.0, 0.0)
    assert lon > -72.0
    assert geodesy.to_local(lat, lon) == pytest.approx((5000.0, 0.0), abs=1e-3)


@pytest.mark.parametrize(
    ("lat", "lon", "zone"),
    [(60.0, 5.0, 32), (60.0, 2.0, 31), (78.0, 15.0, 33), (78.0, 25.0, 35), (-33.9, 151.2, 56), (0.0, -180.0, 1)],
)
def test_zone_exceptions(lat: float, lon: float, zone: int) -> None:
    assert utm_zone(lat, lon) == zone


def test_southern_hemisphere_round_trip() -> None:
    geodesy = UTMGeodesy(-33.9, 151.2)
    lat, lon = geodesy.to_geo(250.0, -400.0)
    assert geodesy.to_local(lat, lon) == pytest.approx((250.0, -400.0), abs=1e-6)


def test_bad_origin_is_refused() -> None:
    with pytest.raises(ValueError, match="origin out of range"):
        UTMGeodesy(95.0, 0.0)
