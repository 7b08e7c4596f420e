"""Goby's warped system clock and the conversions between microseconds and SI seconds.

Points in time are integer microseconds since the Unix epoch (Goby's ``MicroTime``/``SystemClock::time_point``)
or float seconds (``SITime``).  With simulation time on, ``now()`` runs ``warp_factor`` times faster than real time,
counted from a reference point that defaults to 00:00 UTC on January 1 of the current year (not the epoch, so a
warped Goby time differs from a warped MOOS time unless ``reference_microtime: 0`` is configured).
"""

from __future__ import annotations

import datetime as dt
import time

_EPOCH = dt.datetime(1970, 1, 1, tzinfo=dt.UTC)
#: Goby's "not a date time" in microseconds.
NOT_A_DATE_TIME = -1


def start_of_year_micro(now_micro: int | None = None) -> int:
    """00:00:00 UTC, January 1 of the year ``now_micro`` (default: the real now) falls in, in µs since the epoch."""
    now = time.time_ns() // 1000 if now_micro is None else now_micro
    year = (_EPOCH + dt.timedelta(microseconds=now)).year
    return si_to_micro((dt.datetime(year, 1, 1, tzinfo=dt.UTC) - _EPOCH).total_seconds())


def _div_toward_zero(value: int, divisor: int) -> int:
    quotient = abs(value) // divisor
    return quotient if value >= 0 else -quotient


class SystemClock:
    """An application's clock; ``configure`` applies ``app.simulation.time`` (Goby's ``SimulatorSettings``).

    Goby keeps this in statics; here each application owns one (``ProcessContext.clock``, configured by
    ``run_application``), so two applications in one process never change each other's time.
    """

    def __init__(self, use_sim_time: bool = False, warp_factor: int = 1, reference_micro: int | None = None) -> None:
        self.use_sim_time = False
        self.warp_factor = 1
        self.reference_micro = start_of_year_micro()
        self.configure(use_sim_time, warp_factor, reference_micro)

    def configure(self, use_sim_time: bool, warp_factor: int = 1, reference_micro: int | None = None) -> None:
        """Set simulation time; ``warp_factor`` must be a positive integer (Goby's is int32)."""
        if int(warp_factor) < 1:
            raise ValueError(f"warp_factor must be >= 1, got {warp_factor}")
        self.use_sim_time = bool(use_sim_time)
        self.warp_factor = int(warp_factor) if use_sim_time else 1
        if reference_micro is not None:
            self.reference_micro = int(reference_micro)

    @property
    def effective_warp(self) -> int:
        """The warp applied to ``now()`` and to thread loop frequencies (1 unless sim time is on)."""
        return self.warp_factor if self.use_sim_time else 1

    def warp(self, real_micro: int) -> int:
        """Real time -> simulated time: ``t0 + warp * (real - t0)``."""
        return self.reference_micro + self.warp_factor * (int(real_micro) - self.reference_micro)

    def unwarp(self, sim_micro: int) -> int:
        """Simulated time -> real time: ``t0 + (sim - t0) / warp``, the division truncating toward zero."""
        return self.reference_micro + _div_toward_zero(int(sim_micro) - self.reference_micro, self.warp_factor)

    def now_micro(self) -> int:
        """Now in µs since the epoch (warped when sim time is on)."""
        real = time.time_ns() // 1000
        return self.warp(real) if self.use_sim_time else real

    def now(self) -> float:
        """Now in SI seconds since the epoch (warped when sim time is on)."""
        return micro_to_si(self.now_micro())

    now_si = now

    def now_datetime(self) -> dt.datetime:
        """Now as an aware UTC ``datetime``."""
        return _EPOCH + dt.timedelta(microseconds=self.now_micro())


def micro_to_si(micro: int) -> float:
    """A point in time or a duration: µs -> seconds."""
    return micro / 1e6


def si_to_micro(seconds: float) -> int:
    """A point in time or a duration: seconds -> µs, truncating toward zero (as a double->int64 cast)."""
    return int(round(seconds * 1e6, 3)) if seconds == seconds else NOT_A_DATE_TIME


def duration_micro_to_si(micro: int) -> float:
    """A duration in µs as SI seconds."""
    return micro / 1e6


def duration_si_to_micro(seconds: float) -> int:
    """A duration in seconds as µs (truncating)."""
    return si_to_micro(seconds)


def duration_to_whole_seconds(micro: int) -> int:
    """``convert_duration<std::chrono::seconds>``: whole seconds, truncating toward zero."""
    return _div_toward_zero(int(micro), 1_000_000)


def micro_to_datetime(micro: int) -> dt.datetime | None:
    """µs since the epoch -> aware UTC ``datetime``; ``-1`` (not a date time) -> ``None``."""
    if micro == NOT_A_DATE_TIME:
        return None
    return _EPOCH + dt.timedelta(microseconds=int(micro))


def datetime_to_micro(when: dt.datetime | None) -> int:
    """Aware (or naive-as-UTC) ``datetime`` -> µs since the epoch; ``None`` -> ``-1``."""
    if when is None:
        return NOT_A_DATE_TIME
    if when.tzinfo is None:
        when = when.replace(tzinfo=dt.UTC)
    delta = when - _EPOCH
    return (delta.days * 86400 + delta.seconds) * 1_000_000 + delta.microseconds


_MONTHS = ("Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec")


def time_str(micro: int) -> str:
    """Boost's default ``ptime`` text, e.g. ``2011-Aug-16 19:36:57.523456`` (``not-a-date-time`` for -1)."""
    when = micro_to_datetime(micro)
    if when is None:
        return "not-a-date-time"
    frac = f".{when.microsecond:06d}" if when.microsecond else ""
    return f"{when.year:04d}-{_MONTHS[when.month - 1]}-{when.day:02d} {when:%H:%M:%S}{frac}"


def file_str(micro: int) -> str:
    """The time rounded to the nearest second in ISO basic form, e.g. ``20110816T193658``."""
    rounded = (int(micro) + 500_000) // 1_000_000 * 1_000_000
    when = micro_to_datetime(rounded)
    assert when is not None
    return when.strftime("%Y%m%dT%H%M%S")

