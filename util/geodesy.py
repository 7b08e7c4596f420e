"""Local x/y grid on UTM, computed the way MOOSGeodesy does it for pHelmIvP and the IvP tools.

Why UTM and not a flat-earth grid: the default MOOS-IvP build defines ``USE_UTM``, so pHelmIvP,
pNodeReporter and uSimMarine all work in UTM metres relative to the origin's projection. Using the same
grid keeps our NAV_X/NAV_Y identical to what a real MOOS-IvP vehicle computes (agreement well under 1 mm
near the origin). The zone is fixed by the origin, as in MOOSGeodesy, so tracks stay continuous when a
vehicle crosses a zone boundary.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from pyproj import Transformer


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
    _forward: Transformer = field(init=False, repr=False, compare=False)
    _inverse: Transformer = field(init=False, repr=False, compare=False)
    _east0: float = field(init=False, repr=False)
    _north0: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not (-90.0 <= self.lat_origin <= 90.0 and -180.0 <= self.lon_origin <= 180.0):
            raise ValueError(f"geodesy origin out of range: lat={self.lat_origin}, lon={self.lon_origin}")
        zone = utm_zone(self.lat_origin, self.lon_origin)
        south = " +south" if self.lat_origin < 0 else ""
        utm = f"+proj=utm +zone={zone} +ellps=WGS84{south}"
        forward = Transformer.from_crs("+proj=latlong +ellps=WGS84", utm, always_xy=True)
        inverse = Transformer.from_crs(utm, "+proj=latlong +ellps=WGS84", always_xy=True)
        east0, north0 = forward.transform(self.lon_origin, self.lat_origin)
        object.__setattr__(self, "zone", zone)
        object.__setattr__(self, "_forward", forward)
        object.__setattr__(self, "_inverse", inverse)
        object.__setattr__(self, "_east0", east0)
        object.__setattr__(self, "_north0", north0)

    @property
    def origin_utm(self) -> tuple[float, float]:
        """(easting, northing) of the origin in its zone."""
        return self._east0, self._north0

    def to_local(self, lat: float, lon: float) -> tuple[float, float]:
        """(x, y) metres east and north of the origin on the origin's UTM grid."""
        east, north = self._forward.transform(lon, lat)
        return east - self._east0, north - self._north0

    def to_geo(self, x: float, y: float) -> tuple[float, float]:
        """(lat, lon) degrees of a local (x, y)."""
        lon, lat = self._inverse.transform(x + self._east0, y + self._north0)
        return lat, lon
