"""UTM local grid against the reference values of ivp_helm.md §7.3 (origin Forest Lake, zone 19T)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.geodesy_reference import ORIGIN, REFERENCE
from util.geodesy import UTMGeodesy, utm_forward, utm_inverse, utm_zone

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


@settings(max_examples=300, deadline=None)
@given(
    lat=st.floats(-80.0, 84.0),
    lon=st.floats(-180.0, 180.0),
    zone_offset=st.integers(-1, 1),
)
def test_our_transverse_mercator_agrees_with_proj(lat: float, lon: float, zone_offset: int) -> None:
    """Our Krüger series against PROJ (pyproj, a test dependency only), on the point's zone and its neighbours."""
    pyproj = pytest.importorskip("pyproj")
    zone = min(60, max(1, utm_zone(lat, lon) + zone_offset))
    south = lat < 0
    utm = f"+proj=utm +zone={zone} +ellps=WGS84{' +south' if south else ''}"
    forward = pyproj.Transformer.from_crs("+proj=latlong +ellps=WGS84", utm, always_xy=True)
    east, north = forward.transform(lon, lat)
    ours = utm_forward(lat, lon, zone, south)
    assert ours[0] == pytest.approx(east, abs=1e-6) and ours[1] == pytest.approx(north, abs=1e-6)
    back_lat, back_lon = utm_inverse(east, north, zone, south)
    assert back_lat == pytest.approx(lat, abs=1e-11)
    assert math.remainder(back_lon - lon, 360.0) == pytest.approx(0.0, abs=1e-11)
