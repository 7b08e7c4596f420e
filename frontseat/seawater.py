"""Seawater properties for ``compute_missing(CTDSample)``: the UNESCO 1983 algorithms Goby uses.

* practical salinity from conductivity ratio (PSS-78, UNESCO tech. paper 44, Perkin & Lewis 1980);
* depth from pressure and latitude (Saunders & Fofonoff, UNESCO 44);
* sound speed (Mackenzie 1981), valid for T -2..30 °C, S 25..40, depth 0..8000 m (else ``ValueError``);
* density from the EOS-80 one-atmosphere equation and secant bulk modulus (Millero & Poisson 1981, UNESCO 38).

Units here are the oceanographic ones the formulas are written in: °C, decibar, metres, S/m.
"""

from __future__ import annotations

import math

#: conductivity of standard seawater, C(35, 15 °C, 0), in S/m (42.914 mS/cm)
STANDARD_CONDUCTIVITY = 4.2914


def _poly(x: float, *coefficients: float) -> float:
    """c0 + c1·x + c2·x² + ... (Horner)."""
    total = 0.0
    for c in reversed(coefficients):
        total = total * x + c
    return total


def salinity_from_ratio(ratio: float, temperature: float, pressure_dbar: float) -> float:
    """PSS-78 practical salinity from the conductivity ratio R = C / C(35, 15, 0)."""
    if ratio <= 5e-4:
        return 0.0
    t, p = temperature, pressure_dbar
    rt35 = _poly(t, 0.6766097, 2.00564e-2, 1.104259e-4, -6.9698e-7, 1.0031e-9)
    pressure_term = _poly(p, 0.0, 2.070e-5, -6.370e-10, 3.989e-15)
    temperature_term = _poly(t, 1.0, 3.426e-2, 4.464e-4) + (0.4215 - 3.107e-3 * t) * ratio
    root = math.sqrt(abs(ratio / (rt35 * (1.0 + pressure_term / temperature_term))))
    dt = t - 15.0
    base = _poly(root, 0.0080, -0.1692, 25.3851, 14.0941, -7.0261, 2.7081)
    correction = _poly(root, 0.0005, -0.0056, -0.0066, -0.0375, 0.0636, -0.0144)
    return base + dt / (1.0 + 0.0162 * dt) * correction


def salinity(conductivity: float, temperature: float, pressure_dbar: float) -> float:
    """PSS-78 practical salinity from conductivity (S/m), temperature (°C) and pressure (dbar)."""
    return salinity_from_ratio(conductivity / STANDARD_CONDUCTIVITY, temperature, pressure_dbar)


def depth(pressure_dbar: float, latitude: float) -> float:
    """Depth (m) of a pressure (dbar) at a latitude (deg)."""
    x = math.sin(math.radians(latitude)) ** 2
    gravity = 9.780318 * (1.0 + (5.2788e-3 + 2.36e-5 * x) * x) + 1.092e-6 * pressure_dbar
    return _poly(pressure_dbar, 0.0, 9.72659, -2.2512e-5, 2.279e-10, -1.82e-15) / gravity


def mackenzie_sound_speed(temperature: float, salinity_: float, depth_m: float) -> float:
    """Sound speed (m/s); ``ValueError`` outside the formula's range of validity."""
    t, s, d = temperature, salinity_, depth_m
    if not (-2 <= t <= 30 and 25 <= s <= 40 and 0 <= d <= 8000):
        raise ValueError(f"Mackenzie 1981 is valid for T -2..30 C, S 25..40, D 0..8000 m; got {t}, {s}, {d}")
    return (
        1448.96 + 4.591 * t - 5.304e-2 * t**2 + 2.374e-4 * t**3 + 1.340 * (s - 35) + 1.630e-2 * d
        + 1.675e-7 * d**2 - 1.025e-2 * t * (s - 35) - 7.139e-13 * t * d**3
    )


def density(salinity_: float, temperature: float, pressure_dbar: float) -> float:
    """In-situ density (kg/m³) by EOS-80."""
    s, t, p = salinity_, temperature, pressure_dbar / 10.0  # the bulk modulus is written in bar
    s15 = abs(s) ** 1.5
    pure = _poly(t, 999.842594, 6.793952e-2, -9.095290e-3, 1.001685e-4, -1.120083e-6, 6.536332e-9)
    surface = (
        pure
        + s * _poly(t, 0.824493, -4.0899e-3, 7.6438e-5, -8.2467e-7, 5.3875e-9)
        + s15 * _poly(t, -5.72466e-3, 1.0227e-4, -1.6546e-6)
        + 4.8314e-4 * s * s
    )
    k0 = (
        _poly(t, 19652.21, 148.4206, -2.327105, 1.360477e-2, -5.155288e-5)
        + s * _poly(t, 54.6746, -0.603459, 1.09987e-2, -6.1670e-5)
        + s15 * _poly(t, 7.944e-2, 1.6483e-2, -5.3009e-4)
    )
    a = _poly(t, 3.239908, 1.43713e-3, 1.16092e-4, -5.77905e-7) + s * _poly(t, 2.2838e-3, -1.0981e-5, -1.6078e-6)
    a += 1.91075e-4 * s15
    b = _poly(t, 8.50935e-5, -6.12293e-6, 5.2787e-8) + s * _poly(t, -9.9348e-7, 2.0816e-8, 9.1697e-10)
    bulk_modulus = k0 + a * p + b * p * p
    return surface / (1.0 - p / bulk_modulus)
