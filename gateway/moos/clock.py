"""MOOS time: warped unix time plus a skew, as ``MOOSLocalTime`` / ``MOOSTime``.

Warp multiplies *absolute* unix time (at warp 10 timestamps are about 1.8e10). libMOOS keeps warp and skew
process-global; here they live in a :class:`MoosClock` object. :data:`DEFAULT_CLOCK` exists for pymoos's API
only: the module functions of ``gateway.moos`` (``time``, ``local_time``, ``set_moos_timewarp``) and ``comms()``
built without a clock share it, so pymoos scripts behave as with pymoos (one warp, one skew per process).
Everything else -- translators, the helm, tools, tests -- gives its client its own clock (``comms(clock=...)``,
``choose_client(..., clock=...)``): then its warp and the skew its client learns stay its own.
"""

from __future__ import annotations

import threading
import time as _time

MAX_WARP = 400.0


class MoosClock:
    """A MOOS clock: ``local_time() = unix * warp``; ``time() = local_time() + skew``."""

    def __init__(self, warp: float = 1.0) -> None:
        self._lock = threading.Lock()
        self._warp = 1.0
        self.skew = 0.0
        self.set_warp(warp)

    @property
    def warp(self) -> float:
        return self._warp

    def set_warp(self, warp: float) -> None:
        """Set the time warp (0 < warp <= 400, as libMOOS allows)."""
        warp = float(warp)
        if not 0.0 < warp <= MAX_WARP:
            raise ValueError(f"time warp {warp} is outside (0, {MAX_WARP}]")
        self._warp = warp

    def local_time(self, apply_warp: bool = True) -> float:
        """``MOOSLocalTime``: unix time, warped unless told otherwise; no skew."""
        now = _time.time()
        return now * self._warp if apply_warp else now

    def time(self, apply_warp: bool = True) -> float:
        """``MOOSTime``: local time plus the skew learned from the DB."""
        return self.local_time(apply_warp) + self.skew

    def update_skew(self, tx_local: float, db_time: float, rx_local: float) -> float:
        """Blend a new skew measurement in, as ``UpdateMOOSSkew`` does (first one taken as is)."""
        measured = db_time - (tx_local + rx_local) / 2.0
        with self._lock:
            self.skew = measured if self.skew == 0.0 else 0.9 * self.skew + 0.1 * measured
            return self.skew

    def sleep(self, moos_seconds: float) -> None:
        """``MOOSPause``: sleep a MOOS-time interval, i.e. ``seconds / warp`` of real time."""
        _time.sleep(moos_seconds / self._warp)


DEFAULT_CLOCK = MoosClock()
"""The process-wide clock of pymoos's API: ``gateway.moos.time()``/``set_moos_timewarp()`` and ``comms()``
built without ``clock=`` (each such client writes the skew it learns here, as libMOOS clients do)."""
