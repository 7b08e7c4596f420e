"""``Translator``: one Goby thread paired with one MOOS client -- the unit a gateway plugin launches.

Why this shape (python-can's bridge is two listeners): the MOOS side (``moos()``: triggers, buffers, the
client) and the Goby side (``goby()``: interprocess/interthread subscriptions) each forward into the other, and
*every* callback of both sides runs on this translator's own thread, never concurrently, so translator code needs
no locks.  The MOOS client lives on the thread's reactor (``comms(reactor=self.reactor)``; no I/O thread): its
socket is one more source the thread waits on, so MOOS mail is dispatched the moment it is read (Goby waits for its
next 10 Hz tick).  With the real pymoos (``GOBY_MOOS_CLIENT=pymoos``) the client keeps its own I/O thread, which
only wakes this thread with ``call_soon``.

The thread wakes only for work: mail, Goby messages, and its tick.  The tick is Goby's 10 Hz x warp for a subclass
that overrides ``loop()``; otherwise its only work is ``GOBY_MOOS_TRANSLATOR_TIME``, so it runs once per simulated
second (:meth:`Translator.tick_frequency_hz`).

Subclass, set up triggers and subscriptions in ``__init__``, and launch it from a plugin's ``load(gateway)``
with ``gateway.launch_thread(MyTranslator)``.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from gateway.goby.portal import MultiThreadApplication, SimpleThread
from gateway.moos import MoosClock, choose_client
from gateway.moos_gateway.protobuf.moos_gateway_config_pb2 import GobyMOOSGatewayConfig
from translators.moos_interface import TIME_PUBLISH_PERIOD_S, TIME_VAR, MOOSInterface

log = logging.getLogger(__name__)

LOOP_FREQUENCY_HZ = 10.0  # Goby hard-codes 10 Hz (poll_frequency is ignored); times the warp factor

__all__ = ["LOOP_FREQUENCY_HZ", "TIME_VAR", "MOOSInterface", "Translator", "translator_plugin"]

PluginHook = Callable[[MultiThreadApplication], None]


class Translator(SimpleThread):
    """Base class for translators: ``goby()`` is the portal side, ``moos()`` the MOOS side.

    Construct it on the thread that runs it (``MultiThreadApplication.launch_thread`` does).  ``run()`` connects
    the MOOS client to ``cfg.moos.server:cfg.moos.port`` as :meth:`translator_name` (Goby connects in the
    constructor; we wait until construction succeeded, so a failing subclass constructor leaves no client
    behind).  Triggers and buffers added before or after the connection are (re-)registered on every connect.

    ``comms_kind`` picks the client (``"ours"``, ``"pymoos"``, ``"auto"``; default ``GOBY_MOOS_CLIENT`` or ours),
    see ``gateway.moos.choose_client``.  Ours lives on this thread's reactor, so its on-connect and on-mail
    callbacks run here directly (and ``comms().wait_until_connected`` cannot wait here: use ``is_connected``).
    """

    def __init__(self, cfg: GobyMOOSGatewayConfig, index: int = -1, *, comms_kind: str | None = None) -> None:
        super().__init__(cfg, self.tick_frequency_hz(), index)
        # Goby3 (moos_plugin_translator.h translator_name()) streams std::this_thread::get_id(), which libstdc++
        # prints as the pthread_t; threading.get_ident() is that same pthread_self() value. With address-space
        # randomisation it differs between processes, so two gateways on one MOOSDB do not clash.
        self._name = f"goby::moos::Translator::{threading.get_ident()}"
        sim = cfg.app.simulation.time
        # Goby's SetMOOSTimeWarp is process-global; our client gets a clock of its own instead, so translators
        # of different gateways (or tests) in one process neither share a warp nor overwrite each other's skew.
        # (The real pymoos has only the process-wide clock: choose_client applies this warp to it.)
        self._moos_clock = MoosClock(float(sim.warp_factor) if sim.use_sim_time else 1.0)
        client = choose_client(comms_kind, clock=self._moos_clock, reactor=self.reactor)
        self._moos = MOOSInterface(
            client.comms,
            None if client.reactor is self.reactor else self.call_soon,  # pymoos: hand over from its I/O thread
            moos_time=client.moos_time,
            goby_time=self.context.clock.now,
            technique=cfg.moos.moos_parser_technique,
        )

    @classmethod
    def tick_frequency_hz(cls) -> float:
        """The loop frequency before warp: Goby's 10 Hz when ``cls`` overrides ``loop()`` (Goby's contract for
        translator code), else once per second -- the base's own tick only posts ``GOBY_MOOS_TRANSLATOR_TIME``
        (once per simulated second, as Goby does from its 10 Hz loop); mail never waits for a tick."""
        return LOOP_FREQUENCY_HZ if cls.loop is not Translator.loop else 1.0 / TIME_PUBLISH_PERIOD_S

    def goby(self) -> Translator:
        """The Goby side: ``goby().interprocess()`` / ``goby().interthread()`` publish and subscribe.

        Subscription callbacks run on this translator's thread (the same thread as every MOOS trigger).
        """
        return self

    def moos(self) -> MOOSInterface:
        """The MOOS side: ``add_trigger``, ``add_wildcard_trigger``, ``add_buffer``, ``buffer()``, ``comms()``."""
        return self._moos

    def moos_clock(self) -> MoosClock:
        """This translator's MOOS clock (the configured warp, and the skew its client learns); use
        ``moos().moos_time()`` rather than the process-wide ``gateway.moos.time()`` in translator code."""
        return self._moos_clock

    def translator_name(self) -> str:
        """``goby::moos::Translator::<thread id>``: this translator's MOOS client name (unique on the host)."""
        return self._name

    def run(self) -> None:
        """Start the MOOS client (it connects from this thread's reactor, without blocking), then the thread's loop
        (``initialize``, ``loop`` at :meth:`tick_frequency_hz` x warp, ``finalize``)."""
        cfg = self.cfg()
        self._moos.start(cfg.moos.server, cfg.moos.port, self._name)
        log.info("%s: MOOS client started for %s:%d", self._name, cfg.moos.server, cfg.moos.port)
        super().run()

    def loop(self) -> None:
        """The tick: posts ``GOBY_MOOS_TRANSLATOR_TIME`` about once per simulated second (mail is handled as it
        arrives, not here).  Runs once per simulated second, or at 10 Hz x warp when a subclass overrides it;
        subclasses that override ``loop`` must call ``super().loop()``.
        """
        self._moos.loop()

    def close(self) -> None:
        """Close the MOOS client (flushing queued notifies), then the Goby transports; idempotent."""
        try:
            self._moos.close()
        finally:
            super().close()

    def cfg(self) -> GobyMOOSGatewayConfig:  # narrowed type for translator code
        return super().cfg()

    def __repr__(self) -> str:
        return f"<{type(self).__qualname__} {self._name}>"


def translator_plugin(*translator_classes: type[SimpleThread]) -> tuple[PluginHook, PluginHook]:
    """``load, unload`` for a plugin module whose plugin is these translators, one thread each (Goby's
    ``goby3_moos_gateway_load``/``_unload``): ``load, unload = translator_plugin(MyTranslator)``.

    ``load`` launches the threads in order, ``unload`` joins them; both run on the gateway's main thread.
    """

    def load(gateway: MultiThreadApplication) -> None:
        for cls in translator_classes:
            gateway.launch_thread(cls)

    def unload(gateway: MultiThreadApplication) -> None:
        for cls in translator_classes:
            gateway.join_thread(cls)

    return load, unload
