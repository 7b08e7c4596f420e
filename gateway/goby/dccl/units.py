"""DCCL units: read and set a field carrying ``(dccl.field).units`` as a physical quantity (``pint``).

DCCL's protoc plugin gives such a field C++ accessors ``x_with_units()`` / ``set_x_with_units(q)`` over a
``boost::units`` unit built from the field's ``units`` option (``gen_units_class_plugin.h``); here the same unit is
built as a ``pint`` unit and two functions stand for the generated accessors::

    from gateway.goby.dccl.units import set_with_units, with_units, ureg
    set_with_units(report, "speed_over_ground", 7.2 * ureg.km / ureg.hour)   # stored as 2.0 (m/s)
    with_units(report, "speed_over_ground").to("knot")

The unit comes from exactly one of ``base_dimensions`` (letters ``LTMASIKNJB-`` or their names, each with an
optional ``^power``), ``derived_dimensions`` (Boost.Units dimension names joined by ``*`` and ``/``) or ``unit``
(a Boost.Units base unit, ``category::name``), in the field's ``system`` if it sets one, else the message's
``(dccl.msg).unit_system``, scaled by ``prefix``. Nothing here touches the wire: DCCL encodes the plain value.

``pint`` is imported on first use of a unit, so messages without units never load it. Quantities belong to pint's
application registry (``ureg`` here, the same one ``pint.Quantity`` uses).
"""

from __future__ import annotations

import datetime as dt
import math
import re
from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING, Any

from google.protobuf.descriptor import Descriptor, FieldDescriptor
from google.protobuf.message import Message

from gateway.goby.dccl.errors import DcclError
from gateway.goby.portal.timeutil import SystemClock, micro_to_datetime
from util.descriptors import descriptor_of

if TYPE_CHECKING:
    import pint

__all__ = [
    "DimensionError",
    "FieldUnits",
    "UnitsError",
    "field_units",
    "now",
    "set_with_units",
    "to_datetime",
    "to_micro",
    "ureg",
    "with_units",
]


class UnitsError(DcclError):
    """A field without (usable) DCCL units, or a value that cannot be stored in it."""


class DimensionError(UnitsError, ValueError):
    """A quantity whose dimension is not the field's (``NavigationReport.x`` is [length], 3 s is [time])."""

    def __init__(self, field: str, field_dimension: str, value: str, value_dimension: str) -> None:
        super().__init__(f"{field} has dimension {field_dimension}; {value} has dimension {value_dimension}")
        self.field = field
        self.field_dimension = field_dimension
        self.value_dimension = value_dimension


# DCCL's base dimensions (gen_units_class_plugin.h make_dim_bimap): letter -> Boost.Units name.
BASE_DIMENSIONS = {
    "L": "length", "T": "time", "M": "mass", "A": "plane_angle", "S": "solid_angle", "I": "current",
    "K": "temperature", "N": "amount", "J": "luminous_intensity", "B": "information", "-": "dimensionless",
}
_LETTER = {name: letter for letter, name in BASE_DIMENSIONS.items()}

# Boost.Units' derived dimensions (boost/units/physical_dimensions/) as base-dimension powers.
DERIVED_DIMENSIONS: dict[str, dict[str, int]] = {
    "dimensionless": {},
    "absorbed_dose": {"L": 2, "T": -2}, "acceleration": {"L": 1, "T": -2}, "action": {"L": 2, "M": 1, "T": -1},
    "activity": {"T": -1}, "angular_acceleration": {"A": 1, "T": -2},
    "angular_momentum": {"L": 2, "M": 1, "T": -1, "A": -1}, "angular_velocity": {"A": 1, "T": -1},
    "area": {"L": 2}, "capacitance": {"L": -2, "M": -1, "T": 4, "I": 2}, "conductance": {"L": -2, "M": -1, "T": 3, "I": 2},
    "conductivity": {"L": -3, "M": -1, "T": 3, "I": 2}, "dose_equivalent": {"L": 2, "T": -2},
    "dynamic_viscosity": {"L": -1, "M": 1, "T": -1}, "electric_charge": {"T": 1, "I": 1},
    "electric_potential": {"L": 2, "M": 1, "T": -3, "I": -1}, "energy": {"L": 2, "M": 1, "T": -2},
    "energy_density": {"L": -1, "M": 1, "T": -2}, "force": {"L": 1, "M": 1, "T": -2}, "frequency": {"T": -1},
    "heat_capacity": {"L": 2, "M": 1, "T": -2, "K": -1}, "illuminance": {"L": -2, "J": 1, "S": 1},
    "impedance": {"L": 2, "M": 1, "T": -3, "I": -2}, "inductance": {"L": 2, "M": 1, "T": -2, "I": -2},
    "kinematic_viscosity": {"L": 2, "T": -1}, "luminance": {"L": -2, "J": 1}, "luminous_flux": {"J": 1, "S": 1},
    "magnetic_field_intensity": {"L": -1, "I": 1}, "magnetic_flux": {"L": 2, "M": 1, "T": -2, "I": -1},
    "magnetic_flux_density": {"M": 1, "T": -2, "I": -1}, "mass_density": {"L": -3, "M": 1},
    "molar_energy": {"L": 2, "M": 1, "T": -2, "N": -1}, "molar_heat_capacity": {"L": 2, "M": 1, "T": -2, "K": -1, "N": -1},
    "moment_of_inertia": {"L": 2, "M": 1, "A": -2}, "momentum": {"L": 1, "M": 1, "T": -1},
    "permeability": {"L": 1, "M": 1, "T": -2, "I": -2}, "permittivity": {"L": -3, "M": -1, "T": 4, "I": 2},
    "power": {"L": 2, "M": 1, "T": -3}, "pressure": {"L": -1, "M": 1, "T": -2}, "reluctance": {"L": -2, "M": -1, "T": 2, "I": 2},
    "resistance": {"L": 2, "M": 1, "T": -3, "I": -2}, "resistivity": {"L": 3, "M": 1, "T": -3, "I": -2},
    "specific_energy": {"L": 2, "T": -2}, "specific_heat_capacity": {"L": 2, "T": -2, "K": -1},
    "specific_volume": {"L": 3, "M": -1}, "stress": {"L": -1, "M": 1, "T": -2}, "surface_density": {"L": -2, "M": 1},
    "surface_tension": {"M": 1, "T": -2}, "thermal_conductivity": {"L": 1, "M": 1, "T": -3, "K": -1},
    "torque": {"L": 2, "M": 1, "T": -2, "A": -1}, "velocity": {"L": 1, "T": -1}, "volume": {"L": 3},
    "wavenumber": {"L": -1},
}
DERIVED_DIMENSIONS.update({name: {letter: 1} for letter, name in BASE_DIMENSIONS.items() if letter != "-"})

# Units of the base dimensions in each system DCCL names (gen_units_class_plugin.h include_units_headers).
_SI = {"L": "meter", "T": "second", "M": "kilogram", "A": "radian", "S": "steradian", "I": "ampere", "K": "kelvin",
       "N": "mole", "J": "candela", "B": "bit"}
_SYSTEMS: dict[str, dict[str, str]] = {
    "si": _SI, "angle::radian": _SI,
    "cgs": {"L": "centimeter", "M": "gram", "T": "second", "I": "biot"},
    "degree": {"A": "degree"}, "angle::degree": {"A": "degree"},
    "gradian": {"A": "gradian"}, "angle::gradian": {"A": "gradian"},
    "revolution": {"A": "revolution"}, "angle::revolution": {"A": "revolution"},
    "celsius": {"K": "degC"}, "temperature::celsius": {"K": "degC"},
    "fahrenheit": {"K": "degF"}, "temperature::fahrenheit": {"K": "degF"},
}
_SYSTEMS.update({f"boost::units::{name}": table for name, table in list(_SYSTEMS.items()) if "::" not in name})
_RELATIVE = {"degC": "delta_degC", "degF": "delta_degF"}

# Boost.Units base units (``units { unit: "category::name" }``) whose pint name differs from Boost's.
_BASE_UNITS = {
    "imperial::gallon": "imperial_gallon", "imperial::pint": "imperial_pint", "imperial::quart": "imperial_quart",
    "imperial::gill": "imperial_gill", "imperial::fluid_ounce": "imperial_fluid_ounce",
    "imperial::hundredweight": "long_hundredweight", "imperial::ton": "long_ton", "metric::ton": "metric_ton",
    "us::ton": "short_ton", "us::hundredweight": "short_hundredweight", "temperature::celsius": "degC",
    "temperature::fahrenheit": "degF",
}

_PREFIXES = {
    "yotta": 24, "zetta": 21, "exa": 18, "peta": 15, "tera": 12, "giga": 9, "mega": 6, "kilo": 3, "hecto": 2,
    "deka": 1, "deci": -1, "centi": -2, "milli": -3, "micro": -6, "nano": -9, "pico": -12, "femto": -15, "atto": -18,
    "zepto": -21, "yocto": -24,
}
_PREFIX_OF_POWER = {power: name for name, power in _PREFIXES.items()}

_BASE_TERM = re.compile(r"\s*([LTMASIKNJB-]|[a-z_]+?)(?:_base_dimension)?\s*(?:\^\s*([-+]?\d+(?:\.\d*)?))?\s*")
_DERIVED_TERM = re.compile(r"\s*([a-z1_]+?)(?:_dimension)?\s*([*/]|$)")


@cache
def _registry() -> pint.UnitRegistry:
    import pint  # noqa: PLC0415  (lazy: only messages with units pay for pint)

    return pint.get_application_registry().get()


class _Registry:
    """``ureg.km``, ``ureg.Quantity(3, "ft")``: pint's application registry, imported on first attribute access."""

    def __getattr__(self, name: str) -> Any:
        return getattr(_registry(), name)

    def __call__(self, text: str) -> Any:
        return _registry()(text)


#: pint's application registry (lazy): build quantities with it, ``3 * ureg.feet``, ``ureg.Quantity(5, "min")``.
ureg: Any = _Registry()


@dataclass(frozen=True)
class FieldUnits:
    """A field's DCCL units: ``unit`` (a pint ``Unit``), whether the field holds integers, and its name."""

    name: str
    unit: Any
    integer: bool

    @property
    def dimensionality(self) -> str:
        return str(self.unit.dimensionality)


def _parse_base(text: str, where: str) -> dict[str, float]:
    powers: dict[str, float] = {}
    pos = 0
    while pos < len(text):
        match = _BASE_TERM.match(text, pos)
        if not match or match.end() == pos:
            raise UnitsError(f"{where}: cannot parse base_dimensions {text!r} at {text[pos:]!r}")
        name, power = match.group(1), match.group(2)
        letter = name if name in BASE_DIMENSIONS else _LETTER.get(name)
        if letter is None:
            raise UnitsError(f"{where}: unknown base dimension {name!r} in {text!r} "
                             f"(one of {''.join(BASE_DIMENSIONS)} or {', '.join(_LETTER)})")
        if letter != "-":
            powers[letter] = powers.get(letter, 0.0) + (float(power) if power else 1.0)
        pos = match.end()
    if not text.strip():
        raise UnitsError(f"{where}: empty base_dimensions")
    return powers


def _parse_derived(text: str, where: str) -> dict[str, float]:
    powers: dict[str, float] = {}
    sign = 1
    pos = 0
    while pos < len(text):
        match = _DERIVED_TERM.match(text, pos)
        if not match or match.end() == pos:
            raise UnitsError(f"{where}: cannot parse derived_dimensions {text!r} at {text[pos:]!r}")
        dims = DERIVED_DIMENSIONS.get(match.group(1))
        if dims is None:
            raise UnitsError(f"{where}: unknown derived dimension {match.group(1)!r} in {text!r}")
        for letter, power in dims.items():
            powers[letter] = powers.get(letter, 0.0) + sign * power
        sign = -1 if match.group(2) == "/" else 1
        pos = match.end()
    if not text.strip():
        raise UnitsError(f"{where}: empty derived_dimensions")
    return powers


def _system_unit(powers: dict[str, float], system: str, relative: bool, where: str) -> Any:
    table = _SYSTEMS.get(system)
    if table is None:
        raise UnitsError(f"{where}: unit system {system!r} is not supported (one of {', '.join(sorted(_SYSTEMS))})")
    reg = _registry()
    unit = reg.Unit("dimensionless")
    for letter, power in powers.items():
        if power == 0:
            continue
        name = table.get(letter)
        if name is None:
            raise UnitsError(f"{where}: unit system {system!r} has no unit of {BASE_DIMENSIONS[letter]}")
        if name in _RELATIVE and (relative or powers != {letter: 1}):
            name = _RELATIVE[name]
        unit = unit * reg.Unit(name) ** (int(power) if float(power).is_integer() else power)
    return unit


def _with_prefix(unit: Any, prefix: str, where: str) -> Any:
    """``scale<10, p>`` of the whole unit: put the prefix on a factor with power +1 (or the inverse on a -1)."""
    power = _PREFIXES.get(prefix)
    if power is None:
        raise UnitsError(f"{where}: invalid SI prefix {prefix!r}")
    reg = _registry()
    factors = list(unit._units.items())  # pint's UnitsContainer: name -> power
    for sign in (1, -1):
        for i, (name, exponent) in enumerate(factors):
            if exponent == sign and name not in ("degree_Celsius", "degree_Fahrenheit") and not _has_prefix(name):
                scaled = reg.Unit("dimensionless")
                for j, (other, other_exp) in enumerate(factors):
                    term = f"{_PREFIX_OF_POWER[sign * power]}{other}" if i == j else other
                    scaled = scaled * reg.Unit(term) ** other_exp
                return scaled
    raise UnitsError(f"{where}: prefix {prefix!r} on {unit} is not supported")


def _has_prefix(name: str) -> bool:
    return name in ("kilogram",) or any(name.startswith(p) and name != p for p in _PREFIXES)


def _unit_for(field: FieldDescriptor) -> FieldUnits:
    message = field.containing_type
    if message is None:  # a field of a message, always (the stubs allow extensions' None)
        raise UnitsError(f"{field.full_name} belongs to no message")
    where = f"{message.name}.{field.name}"
    options = field.GetOptions()
    from gateway.goby.protobuf.include.dccl import option_extensions_pb2 as dccl_opts  # noqa: PLC0415

    dccl_field = options.Extensions[dccl_opts.field] if options.HasExtension(dccl_opts.field) else None
    if dccl_field is None or not dccl_field.HasField("units"):
        raise UnitsError(f"{where} has no DCCL units ((dccl.field).units)")
    if field.is_repeated:
        raise UnitsError(f"{where} is repeated: with_units reads and sets single fields")
    integer = field.cpp_type in (FieldDescriptor.CPPTYPE_INT32, FieldDescriptor.CPPTYPE_INT64,
                                 FieldDescriptor.CPPTYPE_UINT32, FieldDescriptor.CPPTYPE_UINT64)
    if not integer and field.cpp_type not in (FieldDescriptor.CPPTYPE_DOUBLE, FieldDescriptor.CPPTYPE_FLOAT):
        raise UnitsError(f"{where}: units are only for numeric fields")
    units = dccl_field.units
    given = [name for name in ("base_dimensions", "derived_dimensions", "unit") if units.HasField(name)]
    if len(given) != 1:
        raise UnitsError(f"{where}: units need exactly one of base_dimensions, derived_dimensions or unit "
                         f"({', '.join(given) or 'none'} given)")
    msg_options = message.GetOptions()
    dccl_msg = msg_options.Extensions[dccl_opts.msg] if msg_options.HasExtension(dccl_opts.msg) else None
    if units.HasField("system"):
        system = units.system
    elif dccl_msg is not None and dccl_msg.HasField("unit_system"):
        system = dccl_msg.unit_system
    elif given[0] != "unit":
        raise UnitsError(f"{where}: the field must set units.system or its message (dccl.msg).unit_system")
    else:
        system = "si"
    absolute_temperature = False
    if given[0] == "unit":
        name = units.unit
        pint_name = _BASE_UNITS.get(name, name.rpartition("::")[2])
        try:
            unit = _registry().Unit(pint_name)
        except Exception as exc:  # pint's UndefinedUnitError and parse errors
            raise UnitsError(f"{where}: unknown base unit {name!r}") from exc
        if pint_name in _RELATIVE:
            if units.relative_temperature:
                unit = _registry().Unit(_RELATIVE[pint_name])
            else:
                absolute_temperature = True
    else:
        parse = _parse_base if given[0] == "base_dimensions" else _parse_derived
        powers = parse(getattr(units, given[0]), where)
        unit = _system_unit(powers, system, units.relative_temperature, where)
        absolute_temperature = powers == {"K": 1} and not units.relative_temperature and system != "si"
    if units.HasField("prefix") and units.prefix:
        if absolute_temperature:
            raise UnitsError(f"{where}: 'prefix' is not supported with an absolute temperature field")
        unit = _with_prefix(unit, units.prefix, where)
    return FieldUnits(name=where, unit=unit, integer=integer)


@cache
def _cached_units(field: FieldDescriptor) -> FieldUnits:
    return _unit_for(field)


def _field(msg: Message | type[Message] | Descriptor, field_name: str) -> FieldDescriptor:
    descriptor = msg if isinstance(msg, Descriptor) else descriptor_of(msg)
    field = descriptor.fields_by_name.get(field_name)
    if field is None:
        raise UnitsError(f"{descriptor.name} has no field {field_name!r}")
    return field


def field_units(msg: Message | type[Message] | Descriptor, field_name: str) -> FieldUnits:
    """The DCCL units of ``msg``'s field (a message, its class or its descriptor): ``UnitsError`` if it has none."""
    return _cached_units(_field(msg, field_name))


def with_units(msg: Message, field_name: str) -> Any:
    """The field's value as a pint ``Quantity`` in the field's own unit (DCCL's ``x_with_units()``)."""
    units = field_units(msg, field_name)
    return _registry().Quantity(getattr(msg, field_name), units.unit)


def set_with_units(msg: Message, field_name: str, quantity: Any) -> None:
    """Set the field from a quantity in any unit of the field's dimension (DCCL's ``set_x_with_units(q)``).

    The value is converted to the field's unit; integer fields take the nearest integer. A quantity of another
    dimension raises ``DimensionError``, a plain number, a field without units or a value the field cannot hold
    (out of its type's range, NaN in an integer) ``UnitsError``.
    """
    units = field_units(msg, field_name)
    reg = _registry()
    if not isinstance(quantity, reg.Quantity):
        raise UnitsError(f"{units.name} takes a quantity with units ({units.unit}), not {quantity!r}")
    if quantity.dimensionality != units.unit.dimensionality:
        raise DimensionError(units.name, f"{units.unit.dimensionality} ({units.unit})", f"{quantity}",
                             str(quantity.dimensionality))
    try:
        value = quantity.to(units.unit).magnitude
        if units.integer:
            value = value if isinstance(value, int) else round(value)
        setattr(msg, field_name, value)
    except (ValueError, TypeError, OverflowError) as exc:
        raise UnitsError(f"{units.name} cannot hold {quantity} ({exc})") from exc


def now(clock: SystemClock | None = None) -> Any:
    """``SystemClock::now<MicroTime>()``: integer microseconds since the Unix epoch as a quantity.

    ``clock`` is the application's (``thread.context.clock``: warped when its simulation time is on); without one,
    the real time. ``now(clock).magnitude`` is the MicroTime (an ``int``).
    """
    micro = (clock or SystemClock()).now_micro()
    return _registry().Quantity(micro, "microsecond")


def to_micro(quantity: Any) -> int:
    """A point in time or a duration (any time unit) as integer microseconds (the nearest)."""
    magnitude = quantity.to("microsecond").magnitude
    return magnitude if isinstance(magnitude, int) else int(math.floor(magnitude + 0.5))


def to_datetime(quantity: Any) -> dt.datetime:
    """A point in time (time since the Unix epoch, any time unit) as an aware UTC ``datetime``."""
    when = micro_to_datetime(to_micro(quantity))
    if when is None:
        raise UnitsError(f"{quantity} is Goby's not-a-date-time")
    return when
