"""NODE_REPORT strings: the one codec every producer and consumer of node reports in this repository uses.

Two formats are written:

- :func:`format_course_report`: the Goby3 course's IvPHelmTranslation line that carries a contact to the AUVs,
  ``NAME=..,TYPE=..,TIME=..,X=..,Y=..,DEPTH=..,HDG=..,SPD=..``. The course sets a C++ stream to 15 significant
  digits before TIME and the setting sticks, so every number reads like ``%.15g``.
- :func:`format_local_report`: pNodeReporter's NODE_REPORT_LOCAL, fields in NodeRecord::getSpec order with
  MBUtils' doubleToStringX precisions (X, Y, SPD, HDG, DEP 2 decimals, LAT/LON 8, TIME 2).

One parser, :func:`parse_node_report`, reads the forms pHelmIvP's string2NodeRecord accepts: comma-separated
``KEY=value`` pairs, keys case-insensitive, with the aliases SPD/SPEED, HDG/HEADING, DEP/DEPTH, TIME/UTC_TIME,
ALT/ALTITUDE, LEN/LENGTH, and ``{...}`` kept whole. Where pHelmIvP silently skips a field that is not a number,
this parser rejects the record with a :class:`NodeReportError` naming the field, so nothing is lost unseen.

Numbers are never written in exponent form: MBUtils' isNumber, which pHelmIvP uses on every field, rejects
``-9.3e-10``, so such a field would be dropped without a word.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from decimal import Decimal

from translators.errors import TranslatorError


class NodeReportError(TranslatorError, ValueError):
    """A node report that cannot be parsed or formatted; the message names the field and the reason."""


# MBUtils' isNumber: digits with at most one '.', an optional leading '+' and '-'; no exponent, no blanks.
# (isNumber also lets "--5" through, which atof then reads as 0: rejected here.)
_MOOS_NUMBER = re.compile(r"^\+?-?(\d+\.?\d*|\.\d+)$")

_NUMERIC_KEYS = {
    "TIME": "time", "UTC_TIME": "time", "X": "x", "Y": "y", "LAT": "lat", "LON": "lon",
    "SPD": "speed", "SPEED": "speed", "SPD_OG": "speed_og", "HDG": "heading", "HEADING": "heading",
    "HDG_OG": "heading_og", "YAW": "yaw", "DEP": "depth", "DEPTH": "depth", "ALT": "altitude",
    "ALTITUDE": "altitude", "LENGTH": "length", "LEN": "length",
}
_STRING_KEYS = {
    "NAME": "name", "TYPE": "type", "COLOR": "color", "GROUP": "group", "MODE": "mode", "MODE_AUX": "mode_aux",
    "ALLSTOP": "allstop", "LOAD_WARNING": "load_warning",
}


@dataclass
class NodeReport:
    """The fields of one node report; a number left None was not in the report."""

    name: str = ""
    type: str = ""
    time: float | None = None
    x: float | None = None
    y: float | None = None
    lat: float | None = None
    lon: float | None = None
    speed: float | None = None
    heading: float | None = None
    depth: float | None = None
    yaw: float | None = None
    altitude: float | None = None
    speed_og: float | None = None
    heading_og: float | None = None
    length: float | None = None
    color: str = ""
    group: str = ""
    mode: str = ""
    mode_aux: str = ""
    allstop: str = ""
    load_warning: str = ""
    index: int = 0
    thrust_mode_reverse: bool = False
    trajectory: str = ""
    properties: dict[str, str] = field(default_factory=dict)


# ---- numbers ---------------------------------------------------------------------------------------------------
def is_moos_number(text: str) -> bool:
    """True if pHelmIvP's isNumber accepts ``text`` (no exponent, no blanks)."""
    return bool(_MOOS_NUMBER.match(text))


def _finite(value: float, what: str) -> float:
    if not math.isfinite(value):
        raise NodeReportError(f"{what} = {value} is not a finite number")
    return value


def plain_g15(value: float) -> str:
    """``value`` as ``%.15g`` (a C++ stream at precision 15) prints it, but never in exponent form.

    The same significant digits are written out positionally (``1e+20`` becomes ``100000000000000000000``), and a
    signed zero keeps its sign as C++ prints it (``-0``).
    """
    text = f"{_finite(value, 'number'):.15g}"
    if "e" in text:
        text = format(Decimal(text), "f")
    return text


def course_number(value: float) -> str:
    """A number of the course's NODE_REPORT: rounded to 1e-3, then :func:`plain_g15`.

    The course's values are DCCL-quantised (0.1 m, 1 degree, 0.1 m/s), so the rounding never changes its output;
    it keeps an unquantised value such as ``-9.3e-10`` from printing as 25 digits. An exact signed zero prints
    ``-0``, as the course's ``DEPTH = -z`` does for a vehicle at the surface.
    """
    if value == 0.0:
        return plain_g15(value)
    return plain_g15(round(_finite(value, "number"), 3) + 0.0)  # + 0.0: a tiny negative rounds to 0, not -0


def double_to_string_x(value: float, digits: int = 3) -> str:
    """MBUtils' doubleToStringX: fixed ``digits`` decimals, trailing zeros and a bare point removed, ``-0`` -> ``0``."""
    text = f"{value:.{digits}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def angle360(degrees: float) -> float:
    """``degrees`` in [0, 360); a tiny negative angle gives 0, not 360."""
    heading = math.fmod(_finite(degrees, "heading"), 360.0)
    if heading < 0.0:
        heading += 360.0
        if heading >= 360.0:
            heading = 0.0
    return heading + 0.0  # turns -0.0 into 0.0


# ---- formatting ------------------------------------------------------------------------------------------------
def format_course_report(report: NodeReport) -> str:
    """The course's contact line: ``NAME=..,TYPE=..,TIME=..,X=..,Y=..,DEPTH=..,HDG=..,SPD=..``.

    TIME is :func:`plain_g15` of the value; X, Y, DEPTH, HDG and SPD are :func:`course_number`. HDG is first
    brought into [0, 360) as the course's nav conversion does (359.9999 reads 0, never 360).
    """
    if not report.name:
        raise NodeReportError("NAME is empty")
    numbers = {"TIME": report.time, "X": report.x, "Y": report.y, "DEPTH": report.depth, "HDG": report.heading,
               "SPD": report.speed}
    missing = [key for key, value in numbers.items() if value is None]
    if missing:
        raise NodeReportError(f"{report.name}: the course's format needs {', '.join(missing)}")
    heading = angle360(round(angle360(report.heading), 3))  # type: ignore[arg-type]
    fields = [("NAME", report.name), ("TYPE", report.type), ("TIME", plain_g15(report.time)),  # type: ignore[arg-type]
              ("X", course_number(report.x)), ("Y", course_number(report.y)),  # type: ignore[arg-type]
              ("DEPTH", course_number(report.depth)), ("HDG", course_number(heading)),  # type: ignore[arg-type]
              ("SPD", course_number(report.speed))]  # type: ignore[arg-type]
    return ",".join(f"{key}={value}" for key, value in fields)


def _heading_to_radians(heading: float) -> float:
    """MOOS-IvP's headingToRadians: compass degrees to math radians in [-pi, pi]."""
    rad = (90.0 - heading) * math.pi / 180.0
    if rad > math.pi:
        rad -= 2 * math.pi
    elif rad < -math.pi:
        rad += 2 * math.pi
    return rad


def format_local_report(report: NodeReport, terse: bool = False) -> str:
    """pNodeReporter's report (NodeRecord::getSpec): fields that are not set are left out.

    ``terse`` drops DEP, LAT, LON and YAW, as ``terse_reports = true`` does. YAW, when set, is written from the
    heading (radians, 7 decimals), as NodeRecord does.
    """
    x = double_to_string_x
    parts = [f"NAME={report.name}"]
    for key, value, digits in (("X", report.x, 2), ("Y", report.y, 2), ("SPD", report.speed, 2),
                               ("HDG", report.heading, 2)):
        if value is not None:
            parts.append(f"{key}={x(_finite(value, key), digits)}")
    if not terse:
        for key, value, digits in (("DEP", report.depth, 2), ("LAT", report.lat, 8), ("LON", report.lon, 8)):
            if value is not None:
                parts.append(f"{key}={x(_finite(value, key), digits)}")
    for key, text in (("TYPE", report.type), ("COLOR", report.color), ("GROUP", report.group),
                      ("MODE", report.mode), ("MODE_AUX", report.mode_aux), ("ALLSTOP", report.allstop),
                      ("LOAD_WARNING", report.load_warning)):
        if text:
            parts.append(f"{key}={text}")
    for key, value in (("ALTITUDE", report.altitude), ("SPD_OG", report.speed_og), ("HDG_OG", report.heading_og)):
        if value is not None:
            parts.append(f"{key}={x(_finite(value, key), 2)}")
    if report.index:
        parts.append(f"INDEX={report.index}")
    if report.thrust_mode_reverse:
        parts.append("THRUST_MODE_REVERSE=true")
    if report.yaw is not None and not terse:
        parts.append(f"YAW={x(_heading_to_radians(report.heading or 0.0), 7)}")
    if report.time is not None:
        parts.append(f"TIME={x(_finite(report.time, 'TIME'), 2)}")
    if report.length is not None:
        parts.append(f"LENGTH={x(_finite(report.length, 'LENGTH'), 2)}")
    if report.trajectory:
        parts.append(f"TRAJECTORY={{{report.trajectory}}}")
    parts.extend(f"{key}={value}" for key, value in sorted(report.properties.items()))
    return ",".join(parts)


# ---- parsing ---------------------------------------------------------------------------------------------------
def _split_fields(text: str) -> list[str]:
    """Split at commas outside ``{...}`` (MBUtils' parseStringZ with brace protection)."""
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch == "{":
            depth += 1
        elif ch == "}" and depth > 0:
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return parts


def parse_node_report(text: str) -> NodeReport:
    """The fields of a NODE_REPORT line; :class:`NodeReportError` names the first bad field.

    Keys are case-insensitive and blanks around keys and values are ignored. A numeric field must be a number as
    pHelmIvP reads one (no exponent). Unknown keys are kept in ``properties`` (upper-cased). A repeated key: the last
    one counts, as in pHelmIvP.
    """
    report = NodeReport()
    for part in _split_fields(text):
        if not part.strip():
            continue
        key, sep, value = part.partition("=")
        key, value = key.strip().upper(), value.strip()
        if not sep or not key:
            raise NodeReportError(f"'{part.strip()}' is not KEY=value")
        if key in _NUMERIC_KEYS:
            if not is_moos_number(value):
                raise NodeReportError(f"{key}={value} is not a number")
            setattr(report, _NUMERIC_KEYS[key], float(value.removeprefix("+")))
        elif key in _STRING_KEYS:
            setattr(report, _STRING_KEYS[key], value)
        elif key == "INDEX":
            if not is_moos_number(value):
                raise NodeReportError(f"INDEX={value} is not a number")
            report.index = int(float(value.removeprefix("+")))
        elif key == "THRUST_MODE_REVERSE":
            report.thrust_mode_reverse = value.lower() == "true"
        elif key == "TRAJECTORY":
            report.trajectory = value[1:-1] if value.startswith("{") and value.endswith("}") else value
        else:
            report.properties[key] = value
    return report
