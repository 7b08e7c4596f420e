"""The Translator base with real parts: our MOOSDB (in-process), a goby-broker process, and the gateway
application hosted in-process (``translators.testing.hosted_translators``)."""

from __future__ import annotations

import queue
import re
import sys
import threading
import time
import types
from typing import Any

import pytest

from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.goby.protobuf.app_config_pb2 import AppConfig
from gateway.moos.message import NOTIFY, MoosMessage
from gateway.moos.testing import collect_mail, connected_comms, running_moosdb
from translators.base import Translator
from translators.moos_interface import TIME_VAR, MOOSInterface, time_string
from translators.techniques import Technique
from translators.testing import gateway_config, hosted_translators

EVENTS: queue.Queue[tuple[str, int, Any]] = queue.Queue()


class RecordingTranslator(Translator):
    """Forwards IN (with the buffered B) to Goby and Goby's ``to_moos`` to OUT; records the thread of each call."""

    def __init__(self, cfg) -> None:
        super().__init__(cfg)
        self.ident = threading.get_ident()
        EVENTS.put(("constructed", self.ident, self.translator_name()))
        self.moos().add_buffer("B")
        self.moos().add_trigger("IN", self.on_in)
        self.moos().add_trigger("IN", self.never)  # ignored: Goby keeps the first trigger
        self.moos().add_wildcard_trigger("W_*", "poster", self.on_wild)
        self.goby().interprocess().subscribe("to_moos", str, self.on_goby)

    def on_in(self, msg) -> None:
        b = self.moos().buffer().get("B")
        EVENTS.put(("in", threading.get_ident(), msg.string()))
        EVENTS.put(("threads", threading.get_ident(), sorted(t.name for t in threading.enumerate())))
        self.goby().interprocess().publish("from_moos", f"{msg.string()}|{b.double() if b else 'none'}")

    def never(self, msg) -> None:
        EVENTS.put(("duplicate", threading.get_ident(), msg.string()))

    def on_wild(self, msg) -> None:
        EVENTS.put(("wild", threading.get_ident(), msg.key()))

    def on_goby(self, text: str) -> None:
        EVENTS.put(("goby", threading.get_ident(), text))
        self.moos().comms().notify("OUT", text.upper())


class LoopingTranslator(RecordingTranslator):
    """Same, with a ``loop()`` of its own: it runs at Goby's 10 Hz (x warp); mail still does not wait for it."""

    def loop(self) -> None:
        super().loop()
        EVENTS.put(("loop", threading.get_ident(), None))


class PymoosStandInTranslator(RecordingTranslator):
    """Same, on the ``pymoos`` client kind: the ``pymoos_stand_in`` fixture makes that our client with an I/O thread
    of its own (as the real pymoos has), so its callbacks are handed over to the translator thread."""

    def __init__(self, cfg) -> None:
        Translator.__init__(self, cfg, comms_kind="pymoos")
        self.ident = threading.get_ident()
        EVENTS.put(("constructed", self.ident, self.translator_name()))
        self.moos().add_buffer("B")
        self.moos().add_trigger("IN", self.on_in)
        self.moos().add_trigger("IN", self.never)
        self.moos().add_wildcard_trigger("W_*", "poster", self.on_wild)
        self.goby().interprocess().subscribe("to_moos", str, self.on_goby)


@pytest.fixture
def pymoos_stand_in(monkeypatch: pytest.MonkeyPatch) -> None:
    """A ``pymoos`` module whose ``comms`` is our client without a reactor: callbacks on its own I/O thread."""
    from gateway.moos.client import comms
    from gateway.moos.clock import MoosClock

    clock = MoosClock()
    fake = types.ModuleType("pymoos")
    fake.comms = lambda: comms(clock=clock)  # type: ignore[attr-defined]
    fake.time = clock.time  # type: ignore[attr-defined]
    fake.set_moos_timewarp = clock.set_warp  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "pymoos", fake)


def _events_until(kind: str, count: int = 1, timeout: float = 20.0) -> list[tuple[str, int, Any]]:
    seen: list[tuple[str, int, Any]] = []
    got = 0
    while got < count:
        event = EVENTS.get(timeout=timeout)
        seen.append(event)
        got += event[0] == kind
    return seen


@pytest.fixture
def infrastructure(tmp_path):
    while not EVENTS.empty():
        EVENTS.get_nowait()
    with running_moosdb() as db, broker_process(tmp_path, platform="tb") as broker:
        yield db, broker


def test_tick_frequency_follows_whether_loop_is_overridden():
    """Goby's 10 Hz for translator code with a loop of its own; else once a second (the time variable)."""
    from translators.frontseat.translation import FrontSeatTranslation

    assert RecordingTranslator.tick_frequency_hz() == 1.0
    assert FrontSeatTranslation.tick_frequency_hz() == 1.0
    assert LoopingTranslator.tick_frequency_hz() == 10.0


@pytest.mark.parametrize("translator_class", [RecordingTranslator, LoopingTranslator, PymoosStandInTranslator])
def test_both_directions_on_the_translator_thread(infrastructure, translator_class, request):
    """Every callback runs on the translator's thread. Our client lives on that thread's reactor (no MOOS I/O
    thread); a client with an I/O thread of its own (pymoos's kind) hands mail over to it."""
    if translator_class is PymoosStandInTranslator:
        request.getfixturevalue("pymoos_stand_in")
    db, broker = infrastructure
    cfg = gateway_config(db.port, broker.interprocess_config())
    with PortalClient(broker.interprocess_config(), name="peer") as peer, \
            connected_comms(db.port, "poster", register=["OUT"]) as poster:
        from_moos = peer.collect("from_moos", str)
        assert peer.wait_subscribed()
        with hosted_translators(cfg, translator_class):
            constructed = _events_until("constructed")[-1]
            ident, name = constructed[1], constructed[2]
            # Goby's translator_name(): the constructing thread's std::this_thread::get_id(), i.e. its pthread_t
            assert name == f"goby::moos::Translator::{ident}"
            # MOOS -> Goby: the buffered B rides along with the IN that follows it
            seen: list[str] = []
            for attempt in range(100):  # until the translator has registered (it connects asynchronously)
                poster.notify("B", 7.5)
                poster.notify("IN", f"hello{attempt}")
                if peer.poll_until(lambda: bool(from_moos), 0.2):
                    break
            assert from_moos and from_moos[0].startswith("hello") and from_moos[0].endswith("|7.5")
            events = _events_until("threads")
            assert all(e[1] == ident for e in events if e[0] in ("in", "duplicate", "threads", "loop"))
            assert not [e for e in events if e[0] == "duplicate"]
            # the MOOS I/O thread of this translator's client: none on the reactor, pymoos's kind has one
            io_thread = f"moos-comms-{name}"
            thread_names = next(e[2] for e in events if e[0] == "threads")
            assert (io_thread in thread_names) == (translator_class is PymoosStandInTranslator), thread_names
            # wildcard trigger: name and source globs
            poster.notify("W_ONE", 1.0)
            wild = [e for e in _events_until("wild") if e[0] == "wild"]
            assert wild == [("wild", ident, "W_ONE")]
            # Goby -> MOOS
            peer.publish("to_moos", "abc")
            out = collect_mail(poster, ["OUT"])
            assert [m.string() for m in out] == ["ABC"]
            goby_events = [e for e in _events_until("goby") if e[0] == "goby"]
            assert goby_events == [("goby", ident, "abc")]
            seen.append("ok")
        assert seen == ["ok"]


class FailingTranslator(Translator):
    def __init__(self, cfg) -> None:
        super().__init__(cfg)
        self.moos().add_trigger("IN", print)
        raise RuntimeError("bad translator config")


def test_failing_constructor_leaves_nothing_running(infrastructure):
    from gateway.moos_gateway.application import PluginLoadError

    db, broker = infrastructure
    cfg = gateway_config(db.port, broker.interprocess_config())
    with pytest.raises(PluginLoadError, match="bad translator config"):
        with hosted_translators(cfg, RecordingTranslator, FailingTranslator):
            pass
    # the RecordingTranslator launched before it was stopped again; the leak check of conftest.py verifies
    # that no MOOS client or translator thread is left running


def test_translator_time_variable(infrastructure):
    db, broker = infrastructure
    cfg = gateway_config(db.port, broker.interprocess_config())
    with connected_comms(db.port, "watcher", register=[TIME_VAR]) as watcher, \
            hosted_translators(cfg, RecordingTranslator):
        posts = collect_mail(watcher, [TIME_VAR], until=2, timeout=20)
    assert len(posts) >= 2
    for post in posts:
        assert post.source().startswith("goby::moos::Translator::")
        match = re.fullmatch(r"moostime=([0-9.e+]+),gobytime=([0-9.e+]+)\n", post.string())
        assert match, post.string()
        assert abs(float(match.group(1)) - float(match.group(2))) < 5
    # about once a second (next publish time is incremented by 1 s, not reset)
    assert posts[1].time() - posts[0].time() > 0.5


def test_time_string_format():
    assert time_string(1728590000.12345, 1728590000.12346) == "moostime=1728590000.12345,gobytime=1728590000.12346\n"


class ScriptedComms:
    """Test double for the MOOS client, used only where the real one cannot be made deterministic: it hands
    ``handle_mail`` one prepared batch, so the buffer-before-trigger order within a batch can be asserted."""

    def __init__(self, batch: list[MoosMessage]) -> None:
        self.batch = batch
        self.registered: list[tuple] = []
        self.notified: list[tuple] = []

    def set_on_connect_callback(self, f) -> bool:
        return True

    def set_on_mail_callback(self, f) -> bool:
        return True

    def register(self, *args) -> bool:
        self.registered.append(args)
        return True

    def fetch(self) -> list[MoosMessage]:
        batch, self.batch = self.batch, []
        return batch

    def notify(self, *args) -> bool:
        self.notified.append(args)
        return True

    def notify_binary(self, *args) -> bool:
        self.notified.append(("binary",) + args)
        return True


def _msg(key: str, value: float | str, src: str = "poster") -> MoosMessage:
    msg = MoosMessage.string_msg(NOTIFY, key, value, 0.0) if isinstance(value, str) else \
        MoosMessage.double_msg(NOTIFY, key, value, 0.0)
    msg.raw_src = src.encode()
    return msg


def test_batch_fills_buffers_before_triggers_and_exact_before_wildcard():
    batch = [_msg("SPEED", 1.0), _msg("HEADING", 10.0), _msg("HEADING", 20.0), _msg("SPEED", 2.0),
             _msg("X_Y", "s", src="other")]
    comms = ScriptedComms(batch)
    iface = MOOSInterface(comms, call_soon=lambda fn: fn(), moos_time=lambda: 0.0, goby_time=lambda: 0.0)
    calls: list[tuple[str, float | str]] = []
    iface.add_buffer("HEADING")
    iface.add_trigger("SPEED", lambda m: calls.append(("speed", iface.buffer()["HEADING"].double())))
    iface.add_trigger("X_Y", lambda m: calls.append(("exact", m.string())))
    iface.add_wildcard_trigger("X_*", "oth??", lambda m: calls.append(("wild", m.string())))
    iface.add_wildcard_trigger("X_*", "poster", lambda m: calls.append(("wrong-app", m.string())))
    assert iface.handle_mail() == 5
    # both SPEED triggers see the last HEADING of the batch; the exact trigger of X_Y before its wildcard
    assert calls == [("speed", 20.0), ("speed", 20.0), ("exact", "s"), ("wild", "s")]
    assert ("HEADING", 0) in comms.registered and ("X_*", "poster", 0) in comms.registered
    iface.register_all()
    assert comms.registered.count(("SPEED", 0)) == 2


def test_trigger_exception_does_not_stop_the_batch():
    comms = ScriptedComms([_msg("A", 1.0), _msg("A", 2.0)])
    iface = MOOSInterface(comms, call_soon=lambda fn: fn(), moos_time=lambda: 0.0, goby_time=lambda: 0.0)
    seen: list[float] = []

    def trigger(msg) -> None:
        seen.append(msg.double())
        raise RuntimeError("boom")

    iface.add_trigger("A", trigger)
    assert iface.handle_mail() == 2
    assert seen == [1.0, 2.0]


def test_notify_protobuf_uses_the_configured_technique():
    comms = ScriptedComms([])
    iface = MOOSInterface(comms, call_soon=lambda fn: fn(), moos_time=lambda: 0.0, goby_time=lambda: 0.0,
                          technique=Technique.PREFIXED_PROTOBUF_TEXT_FORMAT)
    iface.notify_protobuf("APP", AppConfig(name="x", simulation={"time": {"warp_factor": 10}}))
    assert comms.notified == [("APP", '@PB[goby.middleware.protobuf.AppConfig] name: "x" simulation { time { '
                                      'warp_factor: 10 } } ')]
    iface.notify_protobuf("BIN", AppConfig(name="x"), Technique.PROTOBUF_NATIVE_ENCODED)
    assert comms.notified[-1] == ("binary", "BIN", AppConfig(name="x").SerializeToString())
    parsed = iface.parse_protobuf(_msg("APP", comms.notified[0][1]), AppConfig())
    assert parsed == AppConfig(name="x", simulation={"time": {"warp_factor": 10}})
    from translators.techniques import TechniqueError

    with pytest.raises(TechniqueError, match="Non-PROTOBUF"):
        iface.notify_protobuf("APP", AppConfig(), Technique.FORMAT)


class PymoosTranslator(Translator):
    def __init__(self, cfg) -> None:
        super().__init__(cfg, comms_kind="pymoos")


def test_asking_for_the_real_pymoos_when_missing_is_a_clear_error(infrastructure):
    from gateway.moos.factory import pymoos_available
    from gateway.moos_gateway.application import PluginLoadError

    if pymoos_available():
        pytest.skip("the real pymoos is installed here")
    db, broker = infrastructure
    with pytest.raises(PluginLoadError, match="the real pymoos was requested but cannot be imported"):
        with hosted_translators(gateway_config(db.port, broker.interprocess_config()), PymoosTranslator):
            pass


def _time_posts(client, count: int = 2) -> list[float]:
    posts = collect_mail(client, [TIME_VAR], until=count, timeout=20)
    assert len(posts) >= count, [p.string() for p in posts]
    return [float(re.match(r"moostime=([0-9.e+]+),", p.string()).group(1)) for p in posts]


def test_translators_with_different_warps_keep_their_own_moos_clocks(tmp_path):
    """Two gateways in one process, each with its own MOOSDB: one on warp 10 (``use_sim_time``), one unwarped.
    Each translator's MOOS time follows its own configuration; neither touches the process-wide MOOS clock."""
    from gateway.moos.clock import DEFAULT_CLOCK

    before = (DEFAULT_CLOCK.warp, DEFAULT_CLOCK.skew)
    with running_moosdb(warp=10) as fast_db, running_moosdb() as plain_db, \
            broker_process(tmp_path, platform="tclock") as broker:
        fast_cfg = gateway_config(fast_db.port, broker.interprocess_config(), app_name="fast_gateway")
        fast_cfg.app.simulation.time.use_sim_time = True
        fast_cfg.app.simulation.time.warp_factor = 10
        plain_cfg = gateway_config(plain_db.port, broker.interprocess_config(), app_name="plain_gateway")
        with connected_comms(fast_db.port, "fast_watcher", register=[TIME_VAR]) as fast_watcher, \
                connected_comms(plain_db.port, "plain_watcher", register=[TIME_VAR]) as plain_watcher, \
                hosted_translators(fast_cfg, Translator) as fast_gw, \
                hosted_translators(plain_cfg, Translator) as plain_gw:
            fast_times, plain_times = _time_posts(fast_watcher), _time_posts(plain_watcher)
            (fast,), (plain,) = fast_gw.threads(), plain_gw.threads()
            assert fast.moos_clock() is not plain.moos_clock()
            assert (fast.moos_clock().warp, plain.moos_clock().warp) == (10.0, 1.0)
            assert (DEFAULT_CLOCK.warp, DEFAULT_CLOCK.skew) == before
            now = time.time()
            assert fast.moos().moos_time() / now == pytest.approx(10.0, rel=1e-3)
            assert plain.moos().moos_time() == pytest.approx(now, abs=5.0)
    for moos_time in fast_times:
        assert moos_time / now == pytest.approx(10.0, rel=1e-3)
    for moos_time in plain_times:
        assert moos_time == pytest.approx(now, abs=30.0)
