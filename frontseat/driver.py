"""The frontseat driver base class: six abstract methods for the vehicle, the state machine for everyone.

Shaped like python-can's ``BusABC``: a driver fills in only what differs per vehicle (how to talk to it and
how to read its state); the base class owns the signals, the timing, the helm state and the interface state
machine of Goby3's ``InterfaceBase`` (see docs/frontseat.md):

* :meth:`do_work` is one tick: check for a state change (at most one transition), then call :meth:`loop`.
* Timeouts count from construction, in the clock's (possibly warped) seconds.
* A driver's :meth:`loop` may raise :class:`HelmErrorException` / :class:`FrontSeatErrorException`.
* A driver does its I/O on :attr:`FrontSeatDriver.reactor`, the host's event loop: it registers its sockets there
  and handles what arrives when it arrives (a NAV fix is emitted at once, not at the next tick).

Threading: a driver object is not thread-safe. The host calls every public method, and the driver emits
every signal, on one thread (the interface's main thread, whose reactor the driver's I/O runs on).
"""

from __future__ import annotations

import abc
import logging
import math
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Protocol

from frontseat import seawater
from frontseat.errors import DriverConfigError, FrontSeatErrorException, HelmErrorException
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from frontseat.protobuf import frontseat_data_pb2 as data_pb
from frontseat.protobuf import frontseat_pb2 as fs_pb
from frontseat.signals import Signal
from gateway.goby.protobuf import geographic_pb2 as geo_pb
from util.geodesy import UTMGeodesy
from util.reactor import Reactor

log = logging.getLogger(__name__)
raw_in_log = logging.getLogger("frontseat.raw.in")
raw_out_log = logging.getLogger("frontseat.raw.out")


class Clock(Protocol):
    """Anything with ``now()`` in seconds: the hosting application's warped clock, a fake in tests."""

    def now(self) -> float: ...


_HOST_REACTOR: ContextVar[Reactor | None] = ContextVar("frontseat_host_reactor", default=None)


@contextmanager
def hosted_on(reactor: Reactor) -> Iterator[Reactor]:
    """Drivers constructed inside the block do their I/O on ``reactor`` (the host's event loop)."""
    token = _HOST_REACTOR.set(reactor)
    try:
        yield reactor
    finally:
        _HOST_REACTOR.reset(token)


def _application_clock() -> Clock:
    """The clock of the application constructing the driver (its ``ProcessContext``), else real time."""
    from gateway.goby.portal import (  # late: pure state-machine users need no portal
        SystemClock,
        current_context,
    )

    context = current_context()
    return context.clock if context is not None else SystemClock()


class FrontSeatDriver(abc.ABC):
    """Base class of every frontseat driver (Goby's ``InterfaceBase``).

    Signals (emitted by the driver from :meth:`loop` or from its I/O callbacks on :attr:`reactor`, on the host's
    main thread):
    ``signal_command_response(CommandResponse)``, ``signal_data_from_frontseat(InterfaceData)``,
    ``signal_raw_from_frontseat(Raw)``, ``signal_raw_to_frontseat(Raw)``; and, emitted by the base class,
    ``signal_state_change(InterfaceState)`` after every transition (and on every error raised).
    """

    def __init__(self, cfg: config_pb.Config, *, clock: Clock | None = None, reactor: Reactor | None = None) -> None:
        self._cfg = config_pb.Config()
        self._cfg.CopyFrom(cfg)
        self._clock: Clock = clock if clock is not None else _application_clock()
        self._reactor = reactor if reactor is not None else _HOST_REACTOR.get()

        self.signal_command_response: Signal[fs_pb.CommandResponse] = Signal("command_response")
        self.signal_data_from_frontseat: Signal[fs_pb.InterfaceData] = Signal("data_from_frontseat")
        self.signal_raw_from_frontseat: Signal[fs_pb.Raw] = Signal("raw_from_frontseat")
        self.signal_raw_to_frontseat: Signal[fs_pb.Raw] = Signal("raw_to_frontseat")
        self.signal_state_change: Signal[fs_pb.InterfaceState.ValueType] = Signal("state_change")
        self.signal_raw_from_frontseat.connect(lambda raw: _log_raw(raw_in_log, raw))
        self.signal_raw_to_frontseat.connect(lambda raw: _log_raw(raw_out_log, raw))

        self._helm_state: fs_pb.HelmState.ValueType = fs_pb.HELM_NOT_RUNNING
        self._state: fs_pb.InterfaceState.ValueType = fs_pb.INTERFACE_STANDBY
        self._start_time = self._clock.now()
        self._last_helm_error: fs_pb.HelmError.ValueType = fs_pb.ERROR_HELM_NONE
        self._last_frontseat_error: fs_pb.FrontSeatError.ValueType = fs_pb.ERROR_FRONTSEAT_NONE
        # An unset origin reads as (0, 0), as proto2 defaults do in Goby.
        self._geodesy = _make_geodesy(self._cfg.origin.lat, self._cfg.origin.lon)

    # ----- the six methods every driver implements -------------------------------------------------------
    @abc.abstractmethod
    def send_command_to_frontseat(self, command: fs_pb.CommandRequest) -> None:
        """Send a command (desired course or a vehicle-specific extension) to the frontseat."""

    @abc.abstractmethod
    def send_data_to_frontseat(self, data: fs_pb.InterfaceData) -> None:
        """Send payload data (e.g. CTD, modem) to the frontseat."""

    @abc.abstractmethod
    def send_raw_to_frontseat(self, raw: fs_pb.Raw) -> None:
        """Send raw bytes or a raw line to the frontseat."""

    @abc.abstractmethod
    def frontseat_state(self) -> fs_pb.FrontSeatState.ValueType:
        """The driver's view of the frontseat (a ``FrontSeatState`` value)."""

    @abc.abstractmethod
    def frontseat_providing_data(self) -> bool:
        """True while the frontseat supplies the required data (at least navigation)."""

    @abc.abstractmethod
    def loop(self) -> None:
        """One tick of driver I/O, called by :meth:`do_work` after the state check."""

    def close(self) -> None:
        """Release the driver's I/O (sockets, threads). Idempotent; the base class holds none."""
        return None

    def __enter__(self) -> FrontSeatDriver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ----- host API ---------------------------------------------------------------------------------------
    @property
    def reactor(self) -> Reactor:
        """The host's event loop, for the driver's sockets and timers (its callbacks run on the host's main thread).

        Given to the constructor, or by the host constructing the driver inside :func:`hosted_on` (the interface
        does); a :class:`DriverConfigError` if neither.
        """
        if self._reactor is None:
            raise DriverConfigError(
                f"{type(self).__name__} does its I/O on its host's reactor: construct it with reactor=... "
                "or inside frontseat.driver.hosted_on(reactor)"
            )
        return self._reactor

    def cfg(self) -> config_pb.Config:
        """The driver's configuration (a copy owned by the driver; treat as read-only)."""
        return self._cfg

    def state(self) -> fs_pb.InterfaceState.ValueType:
        """The interface state (an ``InterfaceState`` value)."""
        return self._state

    def helm_state(self) -> fs_pb.HelmState.ValueType:
        """The last helm state reported with :meth:`set_helm_state` (``HELM_NOT_RUNNING`` until then)."""
        return self._helm_state

    def set_helm_state(self, helm_state: fs_pb.HelmState.ValueType) -> None:
        """Record the helm's state; it is kept until the next report (there is no helm timeout)."""
        self._helm_state = helm_state

    def last_helm_error(self) -> fs_pb.HelmError.ValueType:
        return self._last_helm_error

    def last_frontseat_error(self) -> fs_pb.FrontSeatError.ValueType:
        return self._last_frontseat_error

    def now(self) -> float:
        """Now on the driver's clock (seconds; warped under simulation time)."""
        return self._clock.now()

    def do_work(self) -> None:
        """One tick: at most one state transition, then the driver's :meth:`loop` (skipped if a check raised).

        Exceptions other than the helm/frontseat error exceptions propagate to the caller.
        """
        try:
            self._check_change_state()
            self.loop()
        except HelmErrorException as exc:
            self._last_helm_error = exc.helm_error
            self._state = fs_pb.INTERFACE_HELM_ERROR
            self.signal_state_change.emit(self._state)
        except FrontSeatErrorException as exc:
            self._last_frontseat_error = exc.frontseat_error
            self._state = fs_pb.INTERFACE_FS_ERROR
            self.signal_state_change.emit(self._state)

    def status(self) -> fs_pb.InterfaceStatus:
        """The interface status; error fields only while an error is recorded."""
        status = fs_pb.InterfaceStatus(
            state=self._state,
            frontseat_state=self.frontseat_state(),
            helm_state=self._helm_state,
        )
        if self._last_helm_error != fs_pb.ERROR_HELM_NONE:
            status.helm_error = self._last_helm_error
        if self._last_frontseat_error != fs_pb.ERROR_FRONTSEAT_NONE:
            status.frontseat_error = self._last_frontseat_error
        return status

    def update_utm_datum(self, datum: geo_pb.LatLonPoint) -> None:
        """Move the local grid's origin (``cfg().origin`` stays as configured, as in Goby)."""
        self._geodesy = _make_geodesy(datum.lat, datum.lon)

    @property
    def geodesy(self) -> UTMGeodesy:
        """The UTM grid used by :meth:`compute_missing`."""
        return self._geodesy

    def compute_missing(self, message: data_pb.NodeStatus | data_pb.CTDSample) -> None:
        """Fill what can be derived in a NodeStatus (name, type, time, the missing fix) or a CTDSample."""
        if isinstance(message, data_pb.CTDSample):
            _compute_missing_ctd(message)
        else:
            self._compute_missing_node_status(message)

    def _compute_missing_node_status(self, node_status: data_pb.NodeStatus) -> None:
        if not node_status.HasField("name"):
            node_status.name = self._cfg.name
        if not node_status.HasField("type"):
            node_status.type = self._cfg.type
        if not node_status.HasField("time"):
            node_status.time = self.now()
        has_global, has_local = node_status.HasField("global_fix"), node_status.HasField("local_fix")
        if not has_global and not has_local:
            log.warning("cannot compute_missing on NodeStatus: global_fix and local_fix are both missing")
            return
        if has_local and not has_global:
            local = node_status.local_fix
            if local.HasField("z"):
                node_status.global_fix.depth = -local.z
            node_status.global_fix.lat, node_status.global_fix.lon = self._geodesy.to_geo(local.x, local.y)
        elif has_global and not has_local:
            fix = node_status.global_fix
            if fix.HasField("depth"):
                node_status.local_fix.z = -fix.depth
            if math.isfinite(fix.lat) and math.isfinite(fix.lon):
                node_status.local_fix.x, node_status.local_fix.y = self._geodesy.to_local(fix.lat, fix.lon)
            else:
                node_status.local_fix.x = node_status.local_fix.y = math.nan

    # ----- the state machine ------------------------------------------------------------------------------
    def _check_change_state(self) -> None:
        before = self._state
        state = self._state
        fs_state = self.frontseat_state()
        if state == fs_pb.INTERFACE_STANDBY:
            if self.frontseat_providing_data():
                self._state = fs_pb.INTERFACE_LISTEN
            else:
                self._check_error_states()
        elif state == fs_pb.INTERFACE_LISTEN:
            if fs_state == fs_pb.FRONTSEAT_ACCEPTING_COMMANDS and (
                self._helm_state == fs_pb.HELM_DRIVE or not self._cfg.require_helm
            ):
                self._state = fs_pb.INTERFACE_COMMAND
            else:
                self._check_error_states()
        elif state == fs_pb.INTERFACE_COMMAND:
            if fs_state in (fs_pb.FRONTSEAT_IN_CONTROL, fs_pb.FRONTSEAT_IDLE):
                self._state = fs_pb.INTERFACE_LISTEN
            else:
                self._check_error_states()
        elif state == fs_pb.INTERFACE_HELM_ERROR:
            if self._helm_state == fs_pb.HELM_DRIVE:
                self._last_helm_error = fs_pb.ERROR_HELM_NONE
                self._state = fs_pb.INTERFACE_STANDBY
        elif state == fs_pb.INTERFACE_FS_ERROR:
            error = self._last_frontseat_error
            if error == fs_pb.ERROR_FRONTSEAT_NOT_CONNECTED and fs_state != fs_pb.FRONTSEAT_NOT_CONNECTED:
                self._last_frontseat_error = fs_pb.ERROR_FRONTSEAT_NONE
                self._state = fs_pb.INTERFACE_STANDBY
            elif error == fs_pb.ERROR_FRONTSEAT_NOT_PROVIDING_DATA and self.frontseat_providing_data():
                self._last_frontseat_error = fs_pb.ERROR_FRONTSEAT_NONE
                self._state = fs_pb.INTERFACE_STANDBY
        if self._state != before:
            log.info(
                "interface state %s -> %s",
                fs_pb.InterfaceState.Name(before),
                fs_pb.InterfaceState.Name(self._state),
            )
            self.signal_state_change.emit(self._state)

    def _check_error_states(self) -> None:
        now = self._clock.now()
        if self._helm_state == fs_pb.HELM_PARK:
            raise HelmErrorException(fs_pb.ERROR_HELM_PARKED)
        if (
            self._cfg.require_helm
            and self._helm_state == fs_pb.HELM_NOT_RUNNING
            and (
                self._state == fs_pb.INTERFACE_COMMAND
                or self._start_time + self._cfg.helm_running_timeout < now
            )
        ):
            raise HelmErrorException(fs_pb.ERROR_HELM_NOT_RUNNING)
        if self.frontseat_state() == fs_pb.FRONTSEAT_NOT_CONNECTED and (
            self._state != fs_pb.INTERFACE_STANDBY
            or self._start_time + self._cfg.frontseat_connected_timeout < now
        ):
            raise FrontSeatErrorException(fs_pb.ERROR_FRONTSEAT_NOT_CONNECTED)
        if not self.frontseat_providing_data() and self._state != fs_pb.INTERFACE_STANDBY:
            raise FrontSeatErrorException(fs_pb.ERROR_FRONTSEAT_NOT_PROVIDING_DATA)


def _compute_missing_ctd(ctd: data_pb.CTDSample) -> None:
    """Salinity, depth, sound speed and density from the primary measurements (UNESCO 1983), where unset."""
    pressure_dbar = ctd.pressure / 1e4  # the proto carries pascals
    if not ctd.HasField("salinity"):
        ctd.salinity = seawater.salinity(ctd.conductivity, ctd.temperature, pressure_dbar)
        ctd.salinity_algorithm = data_pb.CTDSample.UNESCO_44_PREKIN_AND_LEWIS_1980
    if not ctd.global_fix.HasField("depth"):
        ctd.global_fix.depth = seawater.depth(pressure_dbar, ctd.global_fix.lat)
    if not ctd.HasField("sound_speed"):
        try:
            ctd.sound_speed = seawater.mackenzie_sound_speed(ctd.temperature, ctd.salinity, ctd.global_fix.depth)
        except ValueError as exc:
            log.warning("sound speed not computed: %s", exc)
            ctd.sound_speed = math.nan
        ctd.sound_speed_algorithm = data_pb.CTDSample.MACKENZIE_1981
    if not ctd.HasField("density"):
        ctd.density = seawater.density(ctd.salinity, ctd.temperature, pressure_dbar)
        ctd.density_algorithm = data_pb.CTDSample.UNESCO_38_MILLERO_AND_POISSON_1981


def _make_geodesy(lat: float, lon: float) -> UTMGeodesy:
    try:
        return UTMGeodesy(lat, lon)
    except ValueError as exc:
        raise DriverConfigError(f"failed to initialise the UTM geodesy at origin ({lat}, {lon}): {exc}") from exc


def _log_raw(logger: logging.Logger, raw: fs_pb.Raw) -> None:
    if not logger.isEnabledFor(logging.DEBUG):
        return
    if raw.type == fs_pb.Raw.RAW_BINARY:
        logger.debug("<%d byte message>", len(raw.raw))
    else:
        text = raw.raw.decode("utf-8", errors="replace")
        logger.debug("%s%s", text, f" ^ {raw.description}" if raw.description else "")
