"""AIS class B reports from NodeStatus, as Goby3's ``AISConverter`` (goby/middleware/ais.h) and AIS ``Encoder``
(goby/util/ais/encode.cpp) build them: pure functions and small classes, no I/O.

- :class:`AISConverter` keeps a vehicle's last ``filter_length`` distinct NodeStatus reports and builds a
  :class:`PositionReport` (type 18) and a :class:`StaticReport` (type 24).  Speed over ground is the vehicle's
  ``speed.over_ground`` when set (Goby's rule), else the mean of the speeds between consecutive reports on the UTM
  grid of the oldest one; course over ground is the circular mean of the headings of those displacements.
- :func:`encode_position` / :func:`encode_static` give the 168-bit payloads (type 24 as parts A and B, each padded
  to 168 bits as Goby does); :func:`to_sentences` armours them into ``!AIVDM`` sentences with checksums, split into
  several sentences (with a sequence id) when the payload exceeds 60 characters.
- :class:`AISFleet` assigns MMSIs from ``mmsi_start`` per vehicle name, in the order first seen.

Every input is range-checked where it enters: NaN, infinite or out-of-range values become the values AIS defines
as "not available" (lat 91, lon 181, SOG 1023, COG 3600, heading 511, second 60); speeds above 102.2 kn are sent
as 1022 ("102.2 kn or more"); angles are wrapped to [0, 360).  Deliberate differences from Goby: with fewer than
two usable reports (or no displacement) COG is "not available" where Goby computes from an empty set; characters
a 6-bit AIS string cannot carry become spaces (Goby writes ``@``, which decoders take as the end of the name).
"""

from __future__ import annotations

import logging
import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from util.geodesy import UTMGeodesy

log = logging.getLogger(__name__)

#: A ``goby.middleware.frontseat.protobuf.NodeStatus`` (frontseat/protobuf/frontseat_data.proto).  Typed loosely
#: because the frontseat layer sits above this one (tests/test_layering.py): only its fields are read.
NodeStatus = Any

MMSI_MAX = 999_999_999  # nine decimal digits (fits the 30-bit field)
KNOTS_PER_MPS = 3600.0 / 1852.0
SHIP_TYPE_OTHER = 90  # Goby's Voyage::TYPE__OTHER
NAME_CHARS = 20
CALLSIGN_CHARS = 7
MAX_PAYLOAD_CHARS = 60  # Goby: (82 - 20 overhead - 2 CR/LF) bytes of an NMEA 0183 sentence

LAT_NOT_AVAILABLE = 91.0
LON_NOT_AVAILABLE = 181.0
SOG_NOT_AVAILABLE = 1023
SOG_MAX = 1022
COG_NOT_AVAILABLE = 3600
HEADING_NOT_AVAILABLE = 511
SECOND_NOT_AVAILABLE = 60


class AISError(ValueError):
    """A report that cannot be encoded (an MMSI out of range, a bad part number)."""


@dataclass(frozen=True)
class PositionReport:
    """A class B position report (type 18); None means "not available"."""

    mmsi: int
    lat: float | None = None  # degrees
    lon: float | None = None  # degrees
    sog: float | None = None  # m/s
    cog: float | None = None  # degrees true
    heading: float | None = None  # degrees true
    second: int | None = None  # UTC second of the fix


@dataclass(frozen=True)
class StaticReport:
    """A class B static data report (type 24, parts A and B)."""

    mmsi: int
    name: str
    ship_type: int = SHIP_TYPE_OTHER
    callsign: str = ""


def _finite(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None


def _valid_latlon(lat: float | None, lon: float | None) -> bool:
    return lat is not None and lon is not None and math.isfinite(lat) and math.isfinite(lon) \
        and -90.0 <= lat <= 90.0 and -180.0 <= lon <= 180.0


class AISConverter:
    """One vehicle's NodeStatus history (the last ``history_length`` distinct reports) turned into AIS reports."""

    def __init__(self, mmsi: int, history_length: int = 2) -> None:
        if history_length < 2:
            raise AISError(f"history length must be >= 2, not {history_length}")
        check_mmsi(mmsi)
        self.mmsi = mmsi
        self._reports: deque[NodeStatus] = deque(maxlen=history_length)
        self._last_wire = b""

    def add_status(self, status: NodeStatus) -> None:
        """Append ``status`` unless it repeats the last one byte for byte (as Goby)."""
        wire = status.SerializePartialToString(deterministic=True)
        if self._reports and wire == self._last_wire:
            return
        self._last_wire = wire
        self._reports.append(status)

    @property
    def empty(self) -> bool:
        return not self._reports

    def latest(self) -> tuple[PositionReport, StaticReport]:
        """The position and static reports of the latest status."""
        if not self._reports:
            raise AISError("no status reports")
        status = self._reports[-1]
        fix = status.global_fix
        lat = fix.lat if fix.HasField("lat") else None
        lon = fix.lon if fix.HasField("lon") else None
        heading = status.pose.heading if status.pose.HasField("heading") else None
        sog_estimate, cog = self._estimate()
        sog = status.speed.over_ground if status.speed.HasField("over_ground") else sog_estimate
        second = None
        if status.HasField("time") and math.isfinite(status.time) and status.time >= 0:
            second = int(status.time) % 60
        pos = PositionReport(self.mmsi, lat, lon, _finite(sog), cog, _finite(heading), second)
        return pos, StaticReport(self.mmsi, status.name.upper())

    def _estimate(self) -> tuple[float | None, float | None]:
        """(mean speed m/s, circular-mean course deg) over consecutive usable reports; None when unknown."""
        usable = [r for r in self._reports if r.global_fix.HasField("lat") and r.global_fix.HasField("lon")
                  and _valid_latlon(r.global_fix.lat, r.global_fix.lon) and math.isfinite(r.time)]
        if len(usable) < 2:
            return None, None
        geo = UTMGeodesy(usable[0].global_fix.lat, usable[0].global_fix.lon)
        speeds: list[float] = []
        cos_sum = sin_sum = 0.0
        moved = 0
        for before, after in zip(usable, usable[1:], strict=False):
            x0, y0 = geo.to_local(before.global_fix.lat, before.global_fix.lon)
            x1, y1 = geo.to_local(after.global_fix.lat, after.global_fix.lon)
            dx, dy = x1 - x0, y1 - y0
            dt = after.time - before.time
            if dt > 0:
                speeds.append(math.hypot(dx, dy) / dt)
            if dx or dy:
                angle = math.atan2(dy, dx)
                cos_sum += math.cos(angle)
                sin_sum += math.sin(angle)
                moved += 1
        sog = sum(speeds) / len(speeds) if speeds else None
        cog = None
        if moved and (cos_sum or sin_sum):
            cog = (90.0 - math.degrees(math.atan2(sin_sum, cos_sum))) % 360.0
        return sog, cog


def check_mmsi(mmsi: int) -> int:
    if not 0 <= mmsi <= MMSI_MAX:
        raise AISError(f"MMSI {mmsi} out of range (0 to {MMSI_MAX})")
    return mmsi


class AISFleet:
    """The vehicles seen so far, each with its converter; MMSIs from ``mmsi_start`` in the order names first appear."""

    def __init__(self, mmsi_start: int, filter_length: int = 2) -> None:
        check_mmsi(mmsi_start)
        if filter_length < 2:
            raise AISError(f"filter_length must be >= 2, not {filter_length}")
        self._next_mmsi = mmsi_start
        self._filter_length = filter_length
        self.vehicles: dict[str, AISConverter] = {}
        self._sequence_id = 0

    def add_status(self, status: NodeStatus) -> AISConverter | None:
        """Record ``status`` under its name; None (logged) when no MMSI is left for a new name."""
        converter = self.vehicles.get(status.name)
        if converter is None:
            if self._next_mmsi > MMSI_MAX:
                log.error("no MMSI left for vehicle %r (the last one, %d, is taken)", status.name, MMSI_MAX)
                return None
            converter = self.vehicles[status.name] = AISConverter(self._next_mmsi, self._filter_length)
            log.info("vehicle %r is MMSI %d", status.name, self._next_mmsi)
            self._next_mmsi += 1
        converter.add_status(status)
        return converter

    def next_sequence_id(self) -> int:
        """The sequential message id of the next multi-sentence message (0-9, as Goby)."""
        current = self._sequence_id
        self._sequence_id = (self._sequence_id + 1) % 10
        return current

    def position_sentences(self, converter: AISConverter) -> list[str]:
        return to_sentences(encode_position(converter.latest()[0]), self.next_sequence_id)

    def static_sentences(self, converter: AISConverter) -> list[str]:
        static = converter.latest()[1]
        return [*to_sentences(encode_static(static, 0), self.next_sequence_id),
                *to_sentences(encode_static(static, 1), self.next_sequence_id)]


# ------------------------------------------------------------------------------------------------ bits
class _Bits:
    """A big-endian bit string built field by field."""

    def __init__(self) -> None:
        self.value = 0
        self.length = 0

    def uint(self, width: int, value: int = 0) -> _Bits:
        self.value = (self.value << width) | (value & ((1 << width) - 1))  # negatives: two's complement
        self.length += width
        return self

    def text(self, width: int, text: str) -> _Bits:
        for ch in sixbit_text(text, width // 6):
            self.uint(6, ch)
        return self


def sixbit_text(text: str, chars: int) -> list[int]:
    """``text`` upper-cased, cut or padded with ``@`` to ``chars`` 6-bit AIS characters; others become spaces."""
    out: list[int] = []
    for ch in text.upper()[:chars]:
        code = ord(ch)
        if 64 <= code <= 95:
            out.append(code - 64)
        elif 32 <= code <= 63:
            out.append(code)
        else:
            out.append(32)
    return out + [0] * (chars - len(out))


def _latlon(value: float | None, limit: float, not_available: float) -> int:
    if value is None or not math.isfinite(value) or not -limit <= value <= limit:
        value = not_available
    return round(value * 600_000)  # 1/10000 minute


def _angle(value: float | None, scale: int, not_available: int) -> int:
    if value is None or not math.isfinite(value):
        return not_available
    scaled = round((value % 360.0) * scale)
    return 0 if scaled >= 360 * scale else scaled


def _sog(mps: float | None) -> int:
    if mps is None or not math.isfinite(mps) or mps < 0:
        return SOG_NOT_AVAILABLE
    return min(round(mps * KNOTS_PER_MPS * 10), SOG_MAX)


def encode_position(pos: PositionReport) -> tuple[int, int]:
    """Type 18 (class B position report) as ``(bits, length)``: 168 bits, Goby's field layout."""
    check_mmsi(pos.mmsi)
    second = pos.second if pos.second is not None and 0 <= pos.second <= 59 else SECOND_NOT_AVAILABLE
    lat, lon = (pos.lat, pos.lon) if _valid_latlon(pos.lat, pos.lon) else (None, None)
    b = _Bits()
    b.uint(6, 18).uint(2).uint(30, pos.mmsi).uint(8).uint(10, _sog(pos.sog))
    b.uint(1, 0)  # position accuracy: low (> 10 m)
    b.uint(28, _latlon(lon, 180.0, LON_NOT_AVAILABLE)).uint(27, _latlon(lat, 90.0, LAT_NOT_AVAILABLE))
    b.uint(12, _angle(pos.cog, 10, COG_NOT_AVAILABLE)).uint(9, _angle(pos.heading, 1, HEADING_NOT_AVAILABLE))
    b.uint(6, second).uint(2)
    b.uint(1, 1)  # CS unit (class B "CS")
    b.uint(1).uint(1).uint(1).uint(1).uint(1)  # display, DSC, band, message 22, assigned
    b.uint(1, 0)  # RAIM
    b.uint(1, 1).uint(19, 393222)  # communication state selector and the fixed "CS" value
    assert b.length == 168
    return b.value, b.length


def encode_static(static: StaticReport, part: int) -> tuple[int, int]:
    """Type 24 part A (``part`` 0: the name) or B (1: ship type, callsign) as ``(bits, length)``, 168 bits each."""
    check_mmsi(static.mmsi)
    if part not in (0, 1):
        raise AISError(f"type 24 part must be 0 (A) or 1 (B), not {part}")
    if not 0 <= static.ship_type <= 255:
        raise AISError(f"ship type {static.ship_type} out of range (0 to 255)")
    b = _Bits().uint(6, 24).uint(2).uint(30, static.mmsi).uint(2, part)
    if part == 0:
        b.text(6 * NAME_CHARS, static.name).uint(8)
    else:
        b.uint(8, static.ship_type).text(18, "XXX").uint(4).uint(20).text(6 * CALLSIGN_CHARS, static.callsign)
        b.uint(9).uint(9).uint(6).uint(6).uint(6)  # dimensions A-D (unknown) and spare
    assert b.length == 168
    return b.value, b.length


# ------------------------------------------------------------------------------------------------ NMEA
def armour(bits: int, length: int) -> tuple[str, int]:
    """The 6-bit ASCII armouring of a bit string: ``(payload, fill bits)``."""
    fill = (-length) % 6
    value = bits << fill
    chars = (length + fill) // 6
    out = []
    for i in range(chars):
        code = (value >> (6 * (chars - 1 - i))) & 0x3F
        code += 48
        if code > 87:
            code += 8
        out.append(chr(code))
    return "".join(out), fill


def nmea_checksum(body: str) -> str:
    """The two hex digits of the XOR of ``body`` (the characters between ``!``/``$`` and ``*``)."""
    x = 0
    for ch in body.encode("ascii"):
        x ^= ch
    return f"{x:02X}"


def to_sentences(payload_bits: tuple[int, int], next_sequence_id: Callable[[], int] | None = None,
                 channel: str = "B") -> list[str]:
    """``!AIVDM`` sentences (without line ending) carrying the payload; ``next_sequence_id()`` is called only
    when more than one sentence is needed."""
    payload, fill = armour(*payload_bits)
    parts = [payload[i:i + MAX_PAYLOAD_CHARS] for i in range(0, len(payload), MAX_PAYLOAD_CHARS)] or [""]
    sequence = ""
    if len(parts) > 1:
        sequence = str(next_sequence_id() if next_sequence_id is not None else 0)
    sentences = []
    for index, part in enumerate(parts, start=1):
        part_fill = fill if index == len(parts) else 0
        body = f"AIVDM,{len(parts)},{index},{sequence},{channel},{part},{part_fill}"
        sentences.append(f"!{body}*{nmea_checksum(body)}")
    return sentences
