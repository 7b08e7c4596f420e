"""The interface state machine (Goby's InterfaceBase), driven tick by tick by a scripted driver double.

The double is the right tool here: the state machine is pure logic over the driver's answers and a clock.
"""

from __future__ import annotations

import pytest

from frontseat.driver import FrontSeatDriver
from frontseat.errors import FrontSeatErrorException, HelmErrorException
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from frontseat.protobuf import frontseat_pb2 as fs

TIMEOUT = 10.0


class FakeClock:
    def __init__(self, t: float = 1000.0) -> None:
        self.t = t

    def now(self) -> float:
        return self.t


class ScriptedDriverDouble(FrontSeatDriver):
    """A test double: the frontseat's answers are attributes the test sets between ticks."""

    def __init__(self, cfg: config_pb.Config, clock: FakeClock) -> None:
        super().__init__(cfg, clock=clock)
        self.fs_state = fs.FRONTSEAT_NOT_CONNECTED
        self.providing = False
        self.loop_calls = 0
        self.raise_in_loop: Exception | None = None

    def send_command_to_frontseat(self, command: fs.CommandRequest) -> None:  # pragma: no cover - unused
        pass

    def send_data_to_frontseat(self, data: fs.InterfaceData) -> None:  # pragma: no cover - unused
        pass

    def send_raw_to_frontseat(self, raw: fs.Raw) -> None:  # pragma: no cover - unused
        pass

    def frontseat_state(self) -> int:
        return self.fs_state

    def frontseat_providing_data(self) -> bool:
        return self.providing

    def loop(self) -> None:
        self.loop_calls += 1
        if self.raise_in_loop is not None:
            exc, self.raise_in_loop = self.raise_in_loop, None
            raise exc


def make(require_helm: bool = True, **fields: float) -> tuple[ScriptedDriverDouble, FakeClock]:
    clock = FakeClock()
    cfg = config_pb.Config(require_helm=require_helm, **fields)
    return ScriptedDriverDouble(cfg, clock), clock


def state_after_work(d: ScriptedDriverDouble, passes: int = 1) -> int:
    """``passes`` calls of ``do_work()``, then the interface state."""
    for _ in range(passes):
        d.do_work()
    return d.state()


def to_listen(d: ScriptedDriverDouble) -> None:
    d.fs_state, d.providing = fs.FRONTSEAT_ACCEPTING_COMMANDS, True
    assert state_after_work(d) == fs.INTERFACE_LISTEN


def to_command(d: ScriptedDriverDouble) -> None:
    to_listen(d)
    d.set_helm_state(fs.HELM_DRIVE)
    assert state_after_work(d) == fs.INTERFACE_COMMAND


def test_initial_status_has_no_errors() -> None:
    d, _ = make()
    d.fs_state = fs.FRONTSEAT_IDLE
    st = d.status()
    assert (st.state, st.frontseat_state, st.helm_state) == (
        fs.INTERFACE_STANDBY,
        fs.FRONTSEAT_IDLE,
        fs.HELM_NOT_RUNNING,
    )
    assert not st.HasField("helm_error") and not st.HasField("frontseat_error")


def test_standby_to_listen_on_data_then_command_on_next_tick_never_same_tick() -> None:
    d, _ = make()
    d.set_helm_state(fs.HELM_DRIVE)
    d.fs_state, d.providing = fs.FRONTSEAT_ACCEPTING_COMMANDS, True
    assert state_after_work(d) == fs.INTERFACE_LISTEN
    assert state_after_work(d) == fs.INTERFACE_COMMAND
    assert d.loop_calls == 2


def test_standby_with_data_skips_error_checks_even_when_parked() -> None:
    d, _ = make()
    d.set_helm_state(fs.HELM_PARK)
    d.fs_state, d.providing = fs.FRONTSEAT_IDLE, True
    assert state_after_work(d) == fs.INTERFACE_LISTEN  # no check this tick
    assert state_after_work(d) == fs.INTERFACE_HELM_ERROR
    assert d.last_helm_error() == fs.ERROR_HELM_PARKED


def test_listen_to_command_without_helm_when_not_required() -> None:
    d, _ = make(require_helm=False)
    to_listen(d)
    assert state_after_work(d) == fs.INTERFACE_COMMAND


def test_listen_stays_when_frontseat_not_accepting() -> None:
    d, _ = make()
    d.set_helm_state(fs.HELM_DRIVE)
    d.fs_state, d.providing = fs.FRONTSEAT_IN_CONTROL, True
    assert state_after_work(d, 5) == fs.INTERFACE_LISTEN


def test_listen_to_command_skips_error_checks_even_if_data_stopped() -> None:
    d, _ = make()
    to_listen(d)
    d.set_helm_state(fs.HELM_DRIVE)
    d.providing = False
    assert state_after_work(d) == fs.INTERFACE_COMMAND
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    assert d.last_frontseat_error() == fs.ERROR_FRONTSEAT_NOT_PROVIDING_DATA


@pytest.mark.parametrize("fs_state", [fs.FRONTSEAT_IDLE, fs.FRONTSEAT_IN_CONTROL])
@pytest.mark.parametrize("helm", [fs.HELM_DRIVE, fs.HELM_PARK, fs.HELM_NOT_RUNNING])
def test_command_to_listen_when_frontseat_idle_or_in_control_whatever_the_helm(fs_state: int, helm: int) -> None:
    d, _ = make()
    to_command(d)
    d.fs_state = fs_state
    d.set_helm_state(helm)
    assert state_after_work(d) == fs.INTERFACE_LISTEN


def test_command_helm_not_running_is_immediate_error_when_required() -> None:
    d, _ = make()
    to_command(d)
    d.set_helm_state(fs.HELM_NOT_RUNNING)
    d.do_work()  # well within the helm timeout: in COMMAND it is immediate
    assert d.state() == fs.INTERFACE_HELM_ERROR
    assert d.status().helm_error == fs.ERROR_HELM_NOT_RUNNING


def test_command_helm_not_running_is_fine_when_not_required() -> None:
    d, clock = make(require_helm=False)
    to_listen(d)
    assert state_after_work(d) == fs.INTERFACE_COMMAND
    clock.t += 100
    assert state_after_work(d) == fs.INTERFACE_COMMAND


@pytest.mark.parametrize("where", ["standby", "listen", "command"])
@pytest.mark.parametrize("require_helm", [True, False])
def test_helm_park_is_an_error_in_standby_listen_and_command(where: str, require_helm: bool) -> None:
    d, _ = make(require_helm=require_helm)
    if where == "standby":
        d.fs_state = fs.FRONTSEAT_IDLE
    elif where == "listen":
        to_listen(d)
        d.fs_state = fs.FRONTSEAT_IN_CONTROL
    else:
        to_command(d)
    d.set_helm_state(fs.HELM_PARK)
    assert state_after_work(d) == fs.INTERFACE_HELM_ERROR
    assert d.last_helm_error() == fs.ERROR_HELM_PARKED


def test_helm_error_clears_only_on_drive() -> None:
    d, _ = make()
    d.fs_state = fs.FRONTSEAT_IDLE
    d.set_helm_state(fs.HELM_PARK)
    assert state_after_work(d) == fs.INTERFACE_HELM_ERROR
    d.set_helm_state(fs.HELM_NOT_RUNNING)
    d.providing = True
    for _ in range(3):
        assert state_after_work(d) == fs.INTERFACE_HELM_ERROR
    d.set_helm_state(fs.HELM_DRIVE)
    assert state_after_work(d) == fs.INTERFACE_STANDBY
    assert not d.status().HasField("helm_error")


def test_standby_helm_not_running_only_strictly_after_timeout() -> None:
    d, clock = make(helm_running_timeout=TIMEOUT, frontseat_connected_timeout=1e9)
    start = clock.t
    d.fs_state = fs.FRONTSEAT_IDLE
    clock.t = start + TIMEOUT  # equal: the comparison is strict
    assert state_after_work(d) == fs.INTERFACE_STANDBY
    clock.t = start + TIMEOUT + 1e-3
    assert state_after_work(d) == fs.INTERFACE_HELM_ERROR
    assert d.last_helm_error() == fs.ERROR_HELM_NOT_RUNNING


def test_standby_helm_not_running_never_an_error_when_not_required() -> None:
    d, clock = make(require_helm=False)
    d.fs_state = fs.FRONTSEAT_IDLE
    clock.t += 1000
    assert state_after_work(d) == fs.INTERFACE_STANDBY


def test_listen_helm_not_running_after_timeout_counted_from_start() -> None:
    d, clock = make(helm_running_timeout=TIMEOUT)
    clock.t += 5
    to_listen(d)  # entered LISTEN at start+5; the timeout still counts from start
    d.fs_state = fs.FRONTSEAT_IN_CONTROL
    clock.t += 4
    assert state_after_work(d) == fs.INTERFACE_LISTEN
    clock.t += 1.5
    assert state_after_work(d) == fs.INTERFACE_HELM_ERROR


def test_standby_not_connected_only_after_timeout() -> None:
    d, clock = make(frontseat_connected_timeout=TIMEOUT)
    d.set_helm_state(fs.HELM_DRIVE)
    clock.t += TIMEOUT
    assert state_after_work(d) == fs.INTERFACE_STANDBY
    clock.t += 0.01
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    assert d.status().frontseat_error == fs.ERROR_FRONTSEAT_NOT_CONNECTED


@pytest.mark.parametrize("where", ["listen", "command"])
def test_not_connected_is_immediate_in_listen_and_command(where: str) -> None:
    d, _ = make()
    d.set_helm_state(fs.HELM_DRIVE)
    to_listen(d) if where == "listen" else to_command(d)
    if where == "listen":
        d.fs_state = fs.FRONTSEAT_IN_CONTROL
        assert state_after_work(d) == fs.INTERFACE_LISTEN
    d.fs_state = fs.FRONTSEAT_NOT_CONNECTED
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    assert d.last_frontseat_error() == fs.ERROR_FRONTSEAT_NOT_CONNECTED


def test_not_connected_clears_when_connected_again() -> None:
    d, clock = make()
    d.set_helm_state(fs.HELM_DRIVE)
    clock.t += 2 * TIMEOUT
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    d.fs_state = fs.FRONTSEAT_IDLE
    assert state_after_work(d) == fs.INTERFACE_STANDBY
    assert not d.status().HasField("frontseat_error")


@pytest.mark.parametrize("where", ["listen", "command"])
def test_not_providing_data_in_listen_and_command_clears_when_data_returns(where: str) -> None:
    d, _ = make()
    to_command(d) if where == "command" else to_listen(d)
    if where == "listen":
        d.fs_state = fs.FRONTSEAT_IN_CONTROL
    d.providing = False
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    assert d.last_frontseat_error() == fs.ERROR_FRONTSEAT_NOT_PROVIDING_DATA
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    d.providing = True
    assert state_after_work(d) == fs.INTERFACE_STANDBY
    assert state_after_work(d) == fs.INTERFACE_LISTEN


def test_not_providing_data_never_raised_in_standby() -> None:
    d, clock = make()
    d.set_helm_state(fs.HELM_DRIVE)
    d.fs_state = fs.FRONTSEAT_ACCEPTING_COMMANDS
    for _ in range(3):
        clock.t += 100
        d.do_work()
    assert d.state() == fs.INTERFACE_STANDBY


def test_not_connected_error_is_not_cleared_by_data_alone() -> None:
    d, clock = make()
    d.set_helm_state(fs.HELM_DRIVE)
    clock.t += 2 * TIMEOUT
    d.do_work()
    assert d.last_frontseat_error() == fs.ERROR_FRONTSEAT_NOT_CONNECTED
    d.providing = True  # still NOT_CONNECTED
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR


def test_helm_error_has_priority_over_frontseat_error() -> None:
    d, clock = make()
    clock.t += 2 * TIMEOUT  # both timeouts passed: helm NOT_RUNNING and fs NOT_CONNECTED both hold
    assert state_after_work(d) == fs.INTERFACE_HELM_ERROR
    assert d.last_frontseat_error() == fs.ERROR_FRONTSEAT_NONE


def test_not_connected_has_priority_over_not_providing_data() -> None:
    d, _ = make()
    to_command(d)
    d.fs_state, d.providing = fs.FRONTSEAT_NOT_CONNECTED, False
    d.do_work()
    assert d.last_frontseat_error() == fs.ERROR_FRONTSEAT_NOT_CONNECTED


def test_ignoring_commands_from_loop_never_clears_and_skips_nothing_else() -> None:
    d, _ = make()
    to_command(d)
    d.raise_in_loop = FrontSeatErrorException(fs.ERROR_FRONTSEAT_IGNORING_COMMANDS)
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    assert d.status().frontseat_error == fs.ERROR_FRONTSEAT_IGNORING_COMMANDS
    assert state_after_work(d, 5) == fs.INTERFACE_FS_ERROR


def test_helm_error_raised_by_loop_from_an_error_state_keeps_the_stale_fs_error() -> None:
    d, _ = make()
    to_command(d)
    d.raise_in_loop = FrontSeatErrorException(fs.ERROR_FRONTSEAT_IGNORING_COMMANDS)
    d.do_work()
    d.raise_in_loop = HelmErrorException(fs.ERROR_HELM_PARKED)
    d.do_work()
    st = d.status()
    assert st.state == fs.INTERFACE_HELM_ERROR
    assert (st.helm_error, st.frontseat_error) == (fs.ERROR_HELM_PARKED, fs.ERROR_FRONTSEAT_IGNORING_COMMANDS)


def test_a_raising_check_skips_loop_on_that_tick() -> None:
    d, _ = make()
    to_command(d)
    calls = d.loop_calls
    d.set_helm_state(fs.HELM_PARK)
    assert state_after_work(d) == fs.INTERFACE_HELM_ERROR
    assert d.loop_calls == calls
    d.do_work()  # HELM_ERROR does no checks: loop runs
    assert d.loop_calls == calls + 1


def test_other_exceptions_from_loop_propagate() -> None:
    d, _ = make()
    d.raise_in_loop = RuntimeError("driver bug")
    with pytest.raises(RuntimeError, match="driver bug"):
        d.do_work()
    assert d.state() == fs.INTERFACE_STANDBY


def test_state_change_signal_fires_on_transitions_and_on_every_error() -> None:
    d, _ = make()
    seen: list[int] = []
    d.signal_state_change.connect(seen.append)
    d.fs_state = fs.FRONTSEAT_IDLE
    d.do_work()  # no change
    assert seen == []
    to_command(d)
    d.raise_in_loop = FrontSeatErrorException(fs.ERROR_FRONTSEAT_IGNORING_COMMANDS)
    d.do_work()
    d.raise_in_loop = FrontSeatErrorException(fs.ERROR_FRONTSEAT_IGNORING_COMMANDS)
    d.do_work()
    assert seen == [fs.INTERFACE_LISTEN, fs.INTERFACE_COMMAND, fs.INTERFACE_FS_ERROR, fs.INTERFACE_FS_ERROR]


def test_at_most_one_transition_per_tick_through_a_full_recovery() -> None:
    """FS_ERROR(NOT_CONNECTED) -> STANDBY -> LISTEN -> COMMAND takes exactly three ticks."""
    d, clock = make()
    d.set_helm_state(fs.HELM_DRIVE)
    clock.t += 2 * TIMEOUT
    assert state_after_work(d) == fs.INTERFACE_FS_ERROR
    d.fs_state, d.providing = fs.FRONTSEAT_ACCEPTING_COMMANDS, True
    states = []
    for _ in range(3):
        d.do_work()
        states.append(d.state())
    assert states == [fs.INTERFACE_STANDBY, fs.INTERFACE_LISTEN, fs.INTERFACE_COMMAND]


def test_compute_missing_fills_local_fix_from_global_and_back() -> None:
    from frontseat.protobuf import frontseat_data_pb2 as data_pb
    from util.geodesy import UTMGeodesy

    clock = FakeClock(1234.5)
    cfg = config_pb.Config(name="usv", type=20)
    cfg.origin.lat, cfg.origin.lon = 41.592344, -70.711260
    d = ScriptedDriverDouble(cfg, clock)
    ns = data_pb.NodeStatus()
    ns.global_fix.lat, ns.global_fix.lon, ns.global_fix.depth = 41.6, -70.7, 3.0
    d.compute_missing(ns)
    x, y = UTMGeodesy(41.592344, -70.711260).to_local(41.6, -70.7)
    assert (ns.name, ns.type, ns.time) == ("usv", 20, 1234.5)
    assert ns.local_fix.x == pytest.approx(x, abs=1e-6) and ns.local_fix.y == pytest.approx(y, abs=1e-6)
    assert ns.local_fix.z == -3.0
    back = data_pb.NodeStatus()
    back.local_fix.x, back.local_fix.y, back.local_fix.z = x, y, -3.0
    d.compute_missing(back)
    assert back.global_fix.lat == pytest.approx(41.6, abs=1e-9)
    assert back.global_fix.lon == pytest.approx(-70.7, abs=1e-9)
    assert back.global_fix.depth == 3.0
