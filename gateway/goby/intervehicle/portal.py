"""The intervehicle portal hosted by ``goby-broker`` (gobyd's role): every ``link`` of its ``intervehicle {}``
block on one thread, ``intervehicle``, a portal thread with one set of interprocess sockets on the broker.

Goby runs each link as a thread of its own that polls its driver and MAC at 10 Hz; here the thread sleeps in its
reactor until a link has something to do (docs/intervehicle.md "Threads"):

- each driver's descriptor (the UDP socket, an ether inbox's eventfd) is a reader: ``Link.receive`` runs when a
  datagram arrives;
- each link has one timer at ``Link.next_deadline()`` (the start of its next TDMA slot, or the next ttl expiry),
  moved from the warped clock to the monotonic one and re-armed after anything that touched the link;
- a timer flushes held-back log lines, armed only once a line was held back; a link announces itself twice (at
  start, 2 s later) by one-shot timers.

The application side's groups (``modem_data_out``, ``modem_subscription_forward_tx``) are subscribed once and
handed to every link in turn; what a link reports is published on ``modem_data_in``, ``modem_ack_in``,
``modem_expire_in``, ``subscription_report`` (and the diagnostics ``modem_transmit_result``,
``mac_initiate_transmission``). A Subscription one link receives is handed to every link at once, on this thread
(Goby's ``modem_subscription_forward_rx``, an interthread group, plays this part).

A link whose driver, MAC or timed work raises is reported (ERROR naming the link) and restarted on the same thread
after a back-off, with a new driver and MAC but the old link's queues and subscriptions (``Link.take_over``); while
it waits, publications and subscriptions still reach its queues. It never runs on silently without it (Goby's gobyd
would end). A subscription callback that raises is logged and the links go on, as for any portal callback.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from gateway.goby.acomms.driver import ModemDriver
from gateway.goby.acomms.errors import AcommsError, ModemConfigError
from gateway.goby.acomms.ether import Ether, EtherDriver
from gateway.goby.acomms.mac import ALLOWED_SKEW_S
from gateway.goby.acomms.protobuf.driver_base_pb2 import DRIVER_UDP_MULTICAST, DriverConfig
from gateway.goby.acomms.protobuf.modem_message_pb2 import ModemTransmission
from gateway.goby.acomms.udp_multicast import UDPMulticastDriver
from gateway.goby.intervehicle import groups
from gateway.goby.intervehicle.link import Link, LinkConfig, LinkOutputs
from gateway.goby.intervehicle.protobuf.intervehicle_pb2 import (
    ModemTransmissionWithLinkID,
    PortalConfig,
    Subscription,
    SubscriptionReport,
)
from gateway.goby.intervehicle.protobuf.serializer_transporter_pb2 import SerializerTransporterMessage
from gateway.goby.portal.context import ProcessContext, start_on_thread
from gateway.goby.portal.group import Group
from gateway.goby.portal.thread import SimpleThread
from util.descriptors import enum_type_of
from util.reactor import Timer

log = logging.getLogger(__name__)

#: Real seconds a slot may start late before it is skipped (besides Goby's 2 s warped).
REAL_SKEW_S = 0.5
#: Real seconds after a link starts at which it announces itself (apps then resend their subscriptions).
ANNOUNCE_AGAIN_S = (0.0, 2.0)
#: Real seconds before a failed link is restarted: the n-th failure in a row waits the n-th (then the last) value.
RESTART_BACKOFF_S = (0.5, 2.0, 5.0, 15.0, 30.0)
#: A link that ran this long (real seconds) since its last restart starts the back-off afresh when it fails.
RESTART_RESET_S = 60.0
#: Real seconds a link's timer fires after its deadline: the warped clock is wall time, the timer monotonic, and a
#: slot starts only once the clock has passed it (a timer that still fires early is simply armed again).
TIMER_LAG_S = 0.0005
#: While the start-up probe has not come back, it is sent again on every wake-up of the thread and at the latest
#: after this long, doubling up to a second.
PROBE_RESEND_S = 0.05

Method = Callable[[Link, Any], None]


def make_driver(cfg: DriverConfig, ethers: dict[str, Ether] | None = None) -> ModemDriver:
    """The driver a link's ``driver {}`` block names: DRIVER_UDP_MULTICAST, or ``driver_name: "ether:NAME"``
    (an in-process :class:`Ether` given by the host)."""
    which = cfg.WhichOneof("driver")
    if which == "driver_name" and cfg.driver_name.startswith("ether"):
        name = cfg.driver_name.partition(":")[2] or "ether"
        if ethers is None or name not in ethers:
            raise ModemConfigError(f"driver_name {cfg.driver_name!r}: no in-process ether named {name!r} here "
                                   "(ethers exist only when the portal is created in-process)")
        return EtherDriver(ethers[name])
    if which == "driver_type" and cfg.driver_type == DRIVER_UDP_MULTICAST:
        return UDPMulticastDriver()
    what = cfg.driver_name if which == "driver_name" else enum_type_of(DriverConfig.DESCRIPTOR.fields_by_name[
        "driver_type"]).values_by_number[cfg.driver_type].name
    raise ModemConfigError(f"link driver {what} is not available (use DRIVER_UDP_MULTICAST or driver_name: \"ether\")")


class LinkRunner:
    """One link on the intervehicle thread's reactor: its driver a reader, its timed work timers, its restarts.

    Everything runs on the intervehicle thread; other threads may read ``up``, ``failures`` and ``restarts``.
    """

    def __init__(self, host: IntervehicleThread, cfg: LinkConfig,
                 factory: Callable[[DriverConfig], ModemDriver]) -> None:
        self.host = host
        self.cfg = cfg
        self.modem_id = cfg.modem_id
        self._factory = factory
        self._reactor = host.reactor
        self.link: Link | None = None  # the current link (a failed one stays here until its restart)
        self.up = False  # driver started and registered
        self.failures = 0  # failures since the portal started
        self.restarts = 0  # restarts in the current back-off series
        self._fd: int | None = None
        self._timer: Timer | None = None  # at the link's next deadline
        self._timer_for: float | None = None  # ... that deadline (warped s)
        self._flush_timer: Timer | None = None
        self._held_when_armed = 0
        self._once: list[Timer] = []  # announcements and the pending restart
        self._started_at = 0.0

    # ---------------------------------------------------------------------------------------- lifecycle
    def start(self) -> None:
        """Build the link (taking over the queues of the one before, if any), start its driver and register it;
        raises (with nothing left registered) if any of it fails."""
        clock = self.host.context.clock
        # Goby skips a slot started more than 2 s (warped) late; at high warp on a loaded machine that is a few
        # tens of real milliseconds, so we also allow half a real second (docs/intervehicle.md).
        skew = max(ALLOWED_SKEW_S, REAL_SKEW_S * clock.effective_warp)
        link = Link(self.cfg, self._factory(self.cfg.driver), clock.now, self._outputs(), allowed_skew_s=skew)
        if self.link is not None:
            link.take_over(self.link)
        link.start()
        try:
            link.run_due()  # computes the TDMA schedule (or warns that the cycle is empty); expires what is due
            fd = link.driver.fileno()
            self._reactor.add_reader(fd, self._on_readable)
        except BaseException:
            link.stop()
            raise
        self.link, self._fd, self.up = link, fd, True
        self._started_at = time.monotonic()
        self._held_when_armed = link.held_log_lines
        self._arm()

    def announce(self) -> None:
        """Announce the link on ``subscription_report`` now and again later (applications resend their
        subscriptions when they see it)."""
        for delay in ANNOUNCE_AGAIN_S:
            self._once.append(self._reactor.call_later(delay, lambda: self._guard(self._announce_now)))

    def stop(self) -> None:
        """Stop the driver and drop every timer (the portal is stopping); idempotent."""
        self._down()
        for timer in self._once:
            timer.cancel()
        self._once.clear()

    def _down(self) -> None:
        """Unregister and stop the driver, cancel the link's timers; a failure here is logged, never raised."""
        was_up, self.up = self.up, False
        for timer in (self._timer, self._flush_timer):
            if timer is not None:
                timer.cancel()
        self._timer = self._flush_timer = self._timer_for = None
        if self._fd is not None:
            self._reactor.remove_reader(self._fd)
            self._fd = None
        if was_up and self.link is not None:
            try:
                self.link.stop()
            except Exception as exc:  # noqa: BLE001
                log.error("intervehicle link %d: stopping its driver failed: %s", self.modem_id, exc)

    # ------------------------------------------------------------------------------------------- events
    def _on_readable(self) -> None:
        link = self.link
        if link is not None:
            self._guard(link.receive)

    def _on_due(self) -> None:
        link = self.link
        if link is not None:
            self._guard(link.run_due)

    def _flush(self) -> None:
        link = self.link
        if link is not None:
            link.flush_logs()

    def _announce_now(self) -> None:
        self.host.interprocess().publish(groups.subscription_report, SubscriptionReport(link_modem_id=self.modem_id))

    def deliver(self, method: Method, msg: Any) -> None:
        """A publication from the application side for this link (its queues take it even while it is down)."""
        link = self.link
        if link is None:
            return
        try:
            method(link, msg)
        except Exception:
            log.exception("intervehicle link %d: %s raised; continuing", self.modem_id,
                          getattr(method, "__name__", "a subscription"))
        if self.up:
            self._guard(None)  # the next ttl expiry may have moved

    def _guard(self, fn: Callable[[], object] | None) -> None:
        """Run link work, then re-arm the link's timers; an exception from either restarts the link."""
        if not self.up:
            return
        try:
            if fn is not None:
                fn()
            self._arm()
        except Exception as exc:  # noqa: BLE001 - any failure: reported, then the link is restarted
            self._fail(exc)

    def _arm(self) -> None:
        """Keep the link's timer at its next deadline, and a flush timer while log lines are held back."""
        link = self.link
        if link is None or not self.up:
            return
        deadline = link.next_deadline()
        timer = self._timer
        if deadline is None:
            if timer is not None:
                timer.cancel()
            self._timer_for = None
        elif timer is None or not timer.active or deadline != self._timer_for:
            clock = self.host.context.clock
            at = time.monotonic() + max(0.0, deadline - clock.now()) / clock.effective_warp + TIMER_LAG_S
            if timer is None:
                self._timer = self._reactor.call_at(at, self._on_due)
            else:
                timer.reschedule(at)
            self._timer_for = deadline
        held = link.held_log_lines
        if held > self._held_when_armed and (self._flush_timer is None or not self._flush_timer.active):
            # every line held so far is due within one period; lines held later re-arm it when it fires
            self._held_when_armed = held
            period = max(link.drops.period_s, link.driver.refusals.period_s)
            self._flush_timer = self._reactor.call_later(period, lambda: self._guard(self._flush))

    # ------------------------------------------------------------------------------------------ restarts
    def _fail(self, exc: Exception) -> None:
        self.failures += 1
        self._down()
        if time.monotonic() - self._started_at > RESTART_RESET_S:
            self.restarts = 0
        delay = self._backoff()
        log.error("intervehicle link %d failed (%s: %s); restarting it in %g s (failure %d)", self.modem_id,
                  type(exc).__name__, exc, delay, self.failures)
        log.debug("intervehicle link %d failure", self.modem_id, exc_info=exc)
        self._once.append(self._reactor.call_later(delay, self._restart))

    def _backoff(self) -> float:
        return RESTART_BACKOFF_S[min(self.restarts, len(RESTART_BACKOFF_S) - 1)]

    def _restart(self) -> None:
        self._once = [t for t in self._once if t.active]
        self.restarts += 1
        try:
            self.start()
        except Exception as exc:  # noqa: BLE001 - e.g. the multicast group cannot be joined right now
            delay = self._backoff()
            log.error("intervehicle link %d: restart %d failed (%s: %s); trying again in %g s", self.modem_id,
                      self.restarts, type(exc).__name__, exc, delay)
            self._once.append(self._reactor.call_later(delay, self._restart))
            return
        log.warning("intervehicle link %d restarted (restart %d); its queues and subscriptions were kept",
                    self.modem_id, self.restarts)
        self.announce()

    # ------------------------------------------------------------------------------------------- output
    def _outputs(self) -> LinkOutputs:
        ip = self.host.interprocess()
        with_id = self._with_id
        return LinkOutputs(
            data_in=lambda m: ip.publish(groups.modem_data_in, m),
            ack_in=lambda m: ip.publish(groups.modem_ack_in, m),
            expire_in=lambda m: ip.publish(groups.modem_expire_in, m),
            subscription_rx=self.host.accept_subscription,
            subscription_report=lambda m: ip.publish(groups.subscription_report, m),
            transmitted=lambda m: ip.publish(groups.modem_transmit_result, with_id(m)),
            initiated=lambda m: ip.publish(groups.mac_initiate_transmission, with_id(m)),
        )

    def _with_id(self, msg: ModemTransmission) -> ModemTransmissionWithLinkID:
        return ModemTransmissionWithLinkID(link_modem_id=self.modem_id, data=msg)


class IntervehicleThread(SimpleThread):
    """The broker's intervehicle thread: every link of a ``PortalConfig`` on its reactor, one set of interprocess
    sockets; construct it on the thread that runs it. No ``loop()``: it wakes only for the links' readers and
    timers and for what arrives from the broker."""

    def __init__(self, cfg: PortalConfig, factory: Callable[[DriverConfig], ModemDriver]) -> None:
        super().__init__(cfg)
        self.runners = [LinkRunner(self, link_cfg, factory) for link_cfg in cfg.link]
        ip = self.interprocess()
        ip.subscribe(groups.modem_data_out, SerializerTransporterMessage,
                     lambda m: self._each(Link.buffer_message, m))
        ip.subscribe(groups.modem_subscription_forward_tx, Subscription,
                     lambda m: self._each(Link.forward_subscription, m))

    def _each(self, method: Method, msg: Any) -> None:
        for runner in self.runners:
            runner.deliver(method, msg)

    def accept_subscription(self, sub: Subscription) -> None:
        """A Subscription one link received: every link takes it at once, on this thread (Goby hands it over by
        interthread). Before a link acks the frame that carried it, so a publication prompted by that ack always
        finds the subscriber; a round trip through the broker could lose that race."""
        self._each(Link.accept_subscription, sub)

    def initialize(self) -> None:
        """Start every link (raises ``AcommsError`` naming the first that cannot start, the others stopped), wait
        until our subscriptions reached the broker, then let each link announce itself."""
        for runner in self.runners:
            try:
                runner.start()
            except Exception as exc:
                for started in self.runners:
                    started.stop()
                raise AcommsError(f"intervehicle link {runner.modem_id}: {exc}") from exc
            log.info("intervehicle link %d up (subnet mask 0x%X, %d slot(s))", runner.modem_id,
                     runner.cfg.subnet_mask, len(runner.cfg.mac.slot))
        self._wait_subscribed()
        for runner in self.runners:
            runner.announce()

    def _wait_subscribed(self, timeout_s: float = 10.0) -> None:
        """Return once our subscriptions reached the broker (a probe round trip: the proxy keeps their order), so
        a publication made after the broker reported ready is never missed.

        The probe is lost until our subscription is through, so it is sent again whenever the thread wakes (the
        broker forwarding our subscriptions to our publishing socket is one such wake-up) and at the latest after
        ``PROBE_RESEND_S``, doubling."""
        probe = Group(f"{groups.modem_data_out.name}::_probe_{id(self):x}")
        seen: list[str] = []
        ip = self.interprocess()
        ip.subscribe(probe, str, seen.append, record=False)
        deadline = time.monotonic() + timeout_s
        wait = PROBE_RESEND_S
        while not seen and (left := deadline - time.monotonic()) > 0:
            ip.publish(probe, "probe", record=False)
            self.poll(min(wait, left))
            wait = min(2 * wait, 1.0)
        ip.unsubscribe(probe, str)
        if not seen:
            log.warning("intervehicle links: subscriptions not confirmed by the broker within %g s", timeout_s)

    def finalize(self) -> None:
        for runner in self.runners:
            runner.stop()


class IntervehiclePortal:
    """Runs the links of a ``PortalConfig`` in ``context`` (the broker's) on one thread; ``start()`` returns once
    every link's driver started (raises ``AcommsError`` naming the link otherwise); ``stop()`` is idempotent. A link
    that fails is reported and restarted (see the module docstring)."""

    def __init__(self, cfg: PortalConfig, context: ProcessContext, ethers: dict[str, Ether] | None = None,
                 driver_factory: Callable[[DriverConfig], ModemDriver] | None = None) -> None:
        self.cfg = cfg
        self.context = context
        self._factory = driver_factory or (lambda c: make_driver(c, ethers))
        self._thread: IntervehicleThread | None = None
        self._pythread: threading.Thread | None = None
        self._stopping = threading.Event()
        self._stopped = False

    @property
    def running(self) -> list[LinkRunner]:
        """One runner per configured link, in config order (empty before ``start``)."""
        return list(self._thread.runners) if self._thread is not None else []

    def start(self) -> IntervehiclePortal:
        self.context.release_hold()  # the portal serves others; it never waits for required clients

        def build() -> IntervehicleThread:
            thread = IntervehicleThread(self.cfg, self._factory)
            try:
                thread.initialize()
            except BaseException:
                thread.close()
                raise
            return thread

        thread, pythread = start_on_thread(self.context, build, self._serve, "intervehicle")
        self._thread, self._pythread = thread, pythread
        return self

    def _serve(self, thread: IntervehicleThread) -> None:
        """Run the thread until the portal stops (its reactor catches what handlers raise; the links catch their
        own failures); then stop the links and close the sockets."""
        try:
            while thread.alive:
                try:
                    thread.run_once()
                except Exception as exc:  # noqa: BLE001 - no thread may die: reported, then it goes on
                    log.error("intervehicle thread: %s: %s; going on in 1 s", type(exc).__name__, exc)
                    log.debug("intervehicle thread failure", exc_info=exc)
                    if self._stopping.wait(1.0):
                        break
        finally:
            try:
                thread.finalize()
            finally:
                thread.close()

    def stop(self) -> None:
        if self._stopped:
            return
        self._stopped = True
        self._stopping.set()
        if self._thread is not None:
            self._thread.quit()
        if self._pythread is not None:
            self._pythread.join(10)
