"""Local x/y grid on UTM, computed the way MOOSGeodesy does it for pHelmIvP and the IvP tools.

Why UTM and not a flat-earth grid: the default MOOS-IvP build defines ``USE_UTM``, so pHelmIvP,
pNodeReporter and uSimMarine all work in UTM metres relative to the origin's projection. Using the same
grid keeps our NAV_X/NAV_Y identical to what a real MOOS-IvP vehicle computes (agreement well under 1 mm
near the origin). The zone is fixed by the origin, as in MOOSGeodesy, so tracks stay continuous when a
vehicle crosses a zone boundary.

Why our own transverse Mercator and not pyproj: importing pyproj (PROJ and its database) costs 12.5 MiB of
private memory in every process that converts positions (four per vehicle), more than half of a vehicle's memory
budget; MOOSGeodesy built without PROJ also projects with its own code. This is Krüger's series to sixth order in
n (Karney 2011, "Transverse Mercator with an accuracy of a few nanometers"), exact to well under a millimetre
within several zones of the central meridian; tests/test_geodesy.py checks it against PROJ over the globe.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

_A = 6378137.0  # WGS-84
_F = 1 / 298.257223563
_K0 = 0.9996
_FALSE_EASTING = 500000.0
_FALSE_NORTHING_SOUTH = 10000000.0
_N = _F / (2 - _F)
_E = math.sqrt(_F * (2 - _F))
_E2M = 1 - _E * _E
_RECTIFYING_RADIUS = _A / (1 + _N) * (1 + _N**2 / 4 + _N**4 / 64 + _N**6 / 256)
_ALPHA = (
    _N / 2 - 2 / 3 * _N**2 + 5 / 16 * _N**3 + 41 / 180 * _N**4 - 127 / 288 * _N**5 + 7891 / 37800 * _N**6,
    13 / 48 * _N**2 - 3 / 5 * _N**3 + 557 / 1440 * _N**4 + 281 / 630 * _N**5 - 1983433 / 1935360 * _N**6,
    61 / 240 * _N**3 - 103 / 140 * _N**4 + 15061 / 26880 * _N**5 + 167603 / 181440 * _N**6,
    49561 / 161280 * _N**4 - 179 / 168 * _N**5 + 6601661 / 7257600 * _N**6,
    34729 / 80640 * _N**5 - 3418889 / 1995840 * _N**6,
    212378941 / 319334400 * _N**6,
)
_BETA = (
    _N / 2 - 2 / 3 * _N**2 + 37 / 96 * _N**3 - 1 / 360 * _N**4 - 81 / 512 * _N**5 + 96199 / 604800 * _N**6,
    1 / 48 * _N**2 + 1 / 15 * _N**3 - 437 / 1440 * _N**4 + 46 / 105 * _N**5 - 1118711 / 3870720 * _N**6,
    17 / 480 * _N**3 - 37 / 840 * _N**4 - 209 / 4480 * _N**5 + 5569 / 90720 * _N**6,
    4397 / 161280 * _N**4 - 11 / 504 * _N**5 - 830251 / 7257600 * _N**6,
    4583 / 161280 * _N**5 - 108847 / 3991680 * _N**6,
    20648693 / 638668800 * _N**6,
)


def _conformal_tan(tau: float) -> float:
    """tan of the conformal latitude, from tan of the geodetic latitude."""
    sigma = math.sinh(_E * math.atanh(_E * tau / math.hypot(1.0, tau)))
    return tau * math.hypot(1.0, sigma) - sigma * math.hypot(1.0, tau)


def _geodetic_tan(tau_prime: float) -> float:
    """Inverse of ``_conformal_tan`` by Newton's method (converges in 2-3 steps to machine precision)."""
    tau = tau_prime
    for _ in range(5):
        tau_p = _conformal_tan(tau)
        step = (tau_prime - tau_p) / math.hypot(1.0, tau_p) * (1 + _E2M * tau * tau) / (_E2M * math.hypot(1.0, tau))
        tau += step
        if abs(step) < 1e-14 * max(1.0, abs(tau)):
            break
    return tau


def _central_meridian(zone: int) -> float:
    return (zone - 1) * 6.0 - 180.0 + 3.0


def utm_forward(lat: float, lon: float, zone: int, south: bool) -> tuple[float, float]:
    """(easting, northing) metres of a point on ``zone``'s grid (extended beyond the zone's edges)."""
    lam = math.radians(lon - _central_meridian(zone))
    lam = math.remainder(lam, 2 * math.pi)
    tau_p = _conformal_tan(math.tan(math.radians(lat))) if abs(lat) < 90.0 else math.copysign(math.inf, lat)
    if math.isinf(tau_p):
        xi_p, eta_p = math.copysign(math.pi / 2, lat), 0.0
    else:
        xi_p = math.atan2(tau_p, math.cos(lam))
        eta_p = math.asinh(math.sin(lam) / math.hypot(tau_p, math.cos(lam)))
    xi, eta = xi_p, eta_p
    for j, alpha in enumerate(_ALPHA, start=1):
        xi += alpha * math.sin(2 * j * xi_p) * math.cosh(2 * j * eta_p)
        eta += alpha * math.cos(2 * j * xi_p) * math.sinh(2 * j * eta_p)
    easting = _K0 * _RECTIFYING_RADIUS * eta + _FALSE_EASTING
    northing = _K0 * _RECTIFYING_RADIUS * xi + (_FALSE_NORTHING_SOUTH if south else 0.0)
    return easting, northing


def utm_inverse(easting: float, northing: float, zone: int, south: bool) -> tuple[float, float]:
    """(lat, lon) degrees of a point on ``zone``'s grid."""
    xi = (northing - (_FALSE_NORTHING_SOUTH if south else 0.0)) / (_K0 * _RECTIFYING_RADIUS)
    eta = (easting - _FALSE_EASTING) / (_K0 * _RECTIFYING_RADIUS)
    xi_p, eta_p = xi, eta
    for j, beta in enumerate(_BETA, start=1):
        xi_p -= beta * math.sin(2 * j * xi) * math.cosh(2 * j * eta)
        eta_p -= beta * math.cos(2 * j * xi) * math.sinh(2 * j * eta)
    tau_p = math.sin(xi_p) / math.hypot(math.sinh(eta_p), math.cos(xi_p))
    lam = math.atan2(math.sinh(eta_p), math.cos(xi_p))
    lat = math.degrees(math.atan(_geodetic_tan(tau_p)))
    lon = math.degrees(lam) + _central_meridian(zone)
    return lat, math.remainder(lon, 360.0)


def utm_zone(lat: float, lon: float) -> int:
    """The UTM zone number of a point, with the Norway and Svalbard exceptions (as MOOS's legacy LLtoUTM)."""
    zone = int((lon + 180.0) / 6.0) + 1
    if lon >= 180.0:  # keep 180 E in zone 60, as the legacy code's wrap does
        zone = 60
    if 56.0 <= lat < 64.0 and 3.0 <= lon < 12.0:
        zone = 32
    if 72.0 <= lat < 84.0:
        if 0.0 <= lon < 9.0:
            zone = 31
        elif 9.0 <= lon < 21.0:
            zone = 33
        elif 21.0 <= lon < 33.0:
            zone = 35
        elif 33.0 <= lon < 42.0:
            zone = 37
    return zone


@dataclass(frozen=True)
class UTMGeodesy:
    """Converts between latitude/longitude (degrees, WGS-84) and local x (east) / y (north) metres."""

    lat_origin: float
    lon_origin: float
    zone: int = field(init=False)
    _south: bool = field(init=False, repr=False)
    _east0: float = field(init=False, repr=False)
    _north0: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not (-90.0 <= self.lat_origin <= 90.0 and -180.0 <= self.lon_origin <= 180.0):
            raise ValueError(f"geodesy origin out of range: lat={self.lat_origin}, lon={self.lon_origin}")
        zone = utm_zone(self.lat_origin, self.lon_origin)
        south = self.lat_origin < 0
        east0, north0 = utm_forward(self.lat_origin, self.lon_origin, zone, south)
        object.__setattr__(self, "zone", zone)
        object.__setattr__(self, "_south", south)
        object.__setattr__(self, "_east0", east0)
        object.__setattr__(self, "_north0", north0)

    @property
    def origin_utm(self) -> tuple[float, float]:
        """(easting, northing) of the origin in its zone."""
        return self._east0, self._north0

    def to_local(self, lat: float, lon: float) -> tuple[float, float]:
        """(x, y) metres east and north of the origin on the origin's UTM grid."""
        east, north = utm_forward(lat, lon, self.zone, self._south)
        return east - self._east0, north - self._north0

    def to_geo(self, x: float, y: float) -> tuple[float, float]:
        """(lat, lon) degrees of a local (x, y)."""
        return utm_inverse(x + self._east0, y + self._north0, self.zone, self._south)
