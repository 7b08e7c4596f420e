"""The intervehicle portal hosted by ``goby-broker`` (gobyd's role): one thread per ``link`` of its
``intervehicle {}`` block, each a portal thread with its own interprocess sockets on the broker.

Each :class:`LinkThread` subscribes to the application side's groups (``modem_data_out``,
``modem_subscription_forward_tx``/``_rx``) and publishes what its :class:`~gateway.goby.intervehicle.link.Link`
reports (``modem_data_in``, ``modem_ack_in``, ``modem_expire_in``, ``subscription_report``). Received
Subscriptions go out on ``modem_subscription_forward_rx`` so every link thread sees them, as in Goby.

A link whose thread fails (any exception out of its loop) is reported (ERROR naming the link) and restarted on the
same Python thread after a back-off, with a new driver, MAC and portal sockets but the old link's queues and
subscriptions (``Link.take_over``); it never runs on silently without it (Goby's gobyd would end).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

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
from gateway.goby.portal.context import ProcessContext, current_context, start_on_thread
from gateway.goby.portal.group import Group
from gateway.goby.portal.thread import SimpleThread

log = logging.getLogger(__name__)

#: Real seconds a slot may start late before it is skipped (besides Goby's 2 s warped).
REAL_SKEW_S = 0.5
#: Goby's driver thread loop frequency (warped).
LINK_LOOP_HZ = 10.0
#: ... but at most this often in real time (CPU at high warp; 20 ms is 2 % of a 10 s slot at warp 50).
MAX_REAL_LOOP_HZ = 50.0
#: Real seconds after start at which a link announces itself again (apps then resend their subscriptions).
ANNOUNCE_AGAIN_S = (0.0, 2.0)
#: Real seconds before a failed link is restarted: the n-th failure in a row waits the n-th (then the last) value.
RESTART_BACKOFF_S = (0.5, 2.0, 5.0, 15.0, 30.0)
#: A link that ran this long (real seconds) since its last restart starts the back-off afresh when it fails.
RESTART_RESET_S = 60.0


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
    what = cfg.driver_name if which == "driver_name" else DriverConfig.DESCRIPTOR.fields_by_name[
        "driver_type"].enum_type.values_by_number[cfg.driver_type].name
    raise ModemConfigError(f"link driver {what} is not available (use DRIVER_UDP_MULTICAST or driver_name: \"ether\")")


class LinkThread(SimpleThread):
    """One link's loop (10 Hz warped) and its interprocess plumbing."""

    def __init__(self, cfg: LinkConfig, driver: ModemDriver, previous: Link | None = None) -> None:
        # Goby's 10 Hz warped is 300 Hz real at warp 30: cap it (a slot then starts at most 1/MAX_REAL_LOOP_HZ late)
        context = current_context()
        warp = context.clock.effective_warp if context is not None else 1
        super().__init__(cfg, loop_frequency_hz=min(LINK_LOOP_HZ, MAX_REAL_LOOP_HZ / warp))
        ip = self.interprocess()
        outputs = LinkOutputs(
            data_in=lambda m: ip.publish(groups.modem_data_in, m),
            ack_in=lambda m: ip.publish(groups.modem_ack_in, m),
            expire_in=lambda m: ip.publish(groups.modem_expire_in, m),
            subscription_rx=lambda m: ip.publish(groups.modem_subscription_forward_rx, m),
            subscription_report=lambda m: ip.publish(groups.subscription_report, m),
            transmitted=lambda m: ip.publish(groups.modem_transmit_result, self._with_id(m)),
            initiated=lambda m: ip.publish(groups.mac_initiate_transmission, self._with_id(m)),
        )
        # Goby skips a slot started more than 2 s (warped) late; at high warp on a loaded machine that is a few
        # tens of real milliseconds, so we also allow half a real second (docs/intervehicle.md).
        skew = max(ALLOWED_SKEW_S, REAL_SKEW_S * self.context.clock.effective_warp)
        self.link = Link(cfg, driver, self.context.clock.now, outputs, allowed_skew_s=skew)
        if previous is not None:
            self.link.take_over(previous)
        ip.subscribe(groups.modem_data_out, SerializerTransporterMessage, self.link.buffer_message)
        ip.subscribe(groups.modem_subscription_forward_tx, Subscription, self.link.forward_subscription)
        ip.subscribe(groups.modem_subscription_forward_rx, Subscription, self.link.accept_subscription)
        self._announce = [time.monotonic() + s for s in ANNOUNCE_AGAIN_S]

    def _with_id(self, msg: ModemTransmission) -> ModemTransmissionWithLinkID:
        return ModemTransmissionWithLinkID(link_modem_id=self.link.modem_id, data=msg)

    def initialize(self) -> None:
        self.link.start()
        self._wait_subscribed()

    def _wait_subscribed(self, timeout_s: float = 10.0) -> None:
        """Return once our subscriptions reached the broker (a probe round trip: the proxy keeps their order), so
        a publication made after the broker reported ready is never missed."""
        probe = Group(f"{groups.modem_data_out.name}::_probe_{id(self):x}")
        seen: list[str] = []
        ip = self.interprocess()
        ip.subscribe(probe, str, seen.append, record=False)
        deadline = time.monotonic() + timeout_s
        while not seen and time.monotonic() < deadline:
            ip.publish(probe, "probe", record=False)
            self.poll(0.05)
        ip.unsubscribe(probe, str)
        if not seen:
            log.warning("link %d: subscriptions not confirmed by the broker within %g s", self.link.modem_id,
                        timeout_s)

    def loop(self) -> None:
        if self._announce and time.monotonic() >= self._announce[0]:
            self._announce.pop(0)
            self.interprocess().publish(groups.subscription_report,
                                        SubscriptionReport(link_modem_id=self.link.modem_id))
        self.link.loop()

    def finalize(self) -> None:
        self.link.stop()


@dataclass
class RunningLink:
    """A link and the Python thread that runs it (``thread`` is replaced when the link restarts)."""

    cfg: LinkConfig
    thread: LinkThread
    pythread: threading.Thread | None = None
    failures: int = 0  # thread failures since the portal started
    restarts: int = 0


class IntervehiclePortal:
    """Runs the links of a ``PortalConfig`` in ``context`` (the broker's); ``start()`` returns once every link's
    driver started (raises ``AcommsError`` naming the link otherwise); ``stop()`` is idempotent. A link whose
    thread fails is reported and restarted (see the module docstring)."""

    def __init__(self, cfg: PortalConfig, context: ProcessContext, ethers: dict[str, Ether] | None = None,
                 driver_factory: Callable[[DriverConfig], ModemDriver] | None = None) -> None:
        self.cfg = cfg
        self.context = context
        self._factory = driver_factory or (lambda c: make_driver(c, ethers))
        self._running: list[RunningLink] = []
        self._lock = threading.Lock()  # guards RunningLink.thread against stop() during a restart
        self._stopping = threading.Event()
        self._stopped = False

    @property
    def links(self) -> list[Link]:
        return [r.thread.link for r in self._running]

    @property
    def running(self) -> list[RunningLink]:
        return list(self._running)

    def start(self) -> IntervehiclePortal:
        self.context.release_hold()  # the portal serves others; it never waits for required clients
        try:
            for link_cfg in self.cfg.link:
                self._start_link(link_cfg)
        except BaseException:
            self.stop()
            raise
        return self

    def _build(self, cfg: LinkConfig, previous: Link | None = None) -> LinkThread:
        """A started link thread object (its driver up), built on the calling thread."""
        thread = LinkThread(cfg, self._factory(cfg.driver), previous)
        try:
            thread.initialize()
        except BaseException:
            thread.close()
            raise
        return thread

    def _start_link(self, cfg: LinkConfig) -> None:
        def build() -> RunningLink:
            return RunningLink(cfg, self._build(cfg))

        try:
            running, pythread = start_on_thread(self.context, build, self._supervise,
                                                f"intervehicle-link-{cfg.modem_id}")
        except BaseException as exc:  # reported to start()
            raise AcommsError(f"intervehicle link {cfg.modem_id}: {exc}") from exc
        running.pythread = pythread
        self._running.append(running)
        log.info("intervehicle link %d up (subnet mask 0x%X, %d slot(s))", cfg.modem_id, cfg.subnet_mask,
                 len(cfg.mac.slot))

    def _supervise(self, running: RunningLink) -> None:
        """Run the link until the portal stops; report and restart it whenever its thread fails."""
        while True:
            thread = running.thread
            started = time.monotonic()
            try:
                while thread.alive:
                    thread.run_once()
            except Exception as exc:  # noqa: BLE001 - any failure: reported, then the link is restarted
                running.failures += 1
                failed: BaseException | None = exc
            else:
                failed = None
            self._close_thread(running)
            if failed is None or self._stopping.is_set():
                return
            if time.monotonic() - started > RESTART_RESET_S:
                running.restarts = 0
            while not self._restart(running, failed):
                failed = None  # the restart itself failed (logged); try again after the next back-off

    def _restart(self, running: RunningLink, failed: BaseException | None) -> bool:
        """Wait the back-off, then build the link again; True once it runs again or the portal is stopping."""
        delay = RESTART_BACKOFF_S[min(running.restarts, len(RESTART_BACKOFF_S) - 1)]
        if failed is not None:
            log.error("intervehicle link %d failed (%s: %s); restarting it in %g s (failure %d)",
                      running.cfg.modem_id, type(failed).__name__, failed, delay, running.failures)
            log.debug("intervehicle link %d failure", running.cfg.modem_id, exc_info=failed)
        if self._stopping.wait(delay):
            return True
        running.restarts += 1
        try:
            thread = self._build(running.cfg, running.thread.link)
        except Exception as exc:  # noqa: BLE001 - e.g. the multicast group cannot be joined right now
            log.error("intervehicle link %d: restart %d failed (%s: %s); trying again", running.cfg.modem_id,
                      running.restarts, type(exc).__name__, exc)
            return False
        with self._lock:
            running.thread = thread
            if self._stopping.is_set():
                thread.quit()
        log.warning("intervehicle link %d restarted (restart %d); its queues and subscriptions were kept",
                    running.cfg.modem_id, running.restarts)
        return True

    @staticmethod
    def _close_thread(running: RunningLink) -> None:
        """Stop the link's driver and close its sockets; a failure here is logged, never raised."""
        thread = running.thread
        try:
            thread.finalize()
        except Exception as exc:  # noqa: BLE001
            log.error("intervehicle link %d: stopping its driver failed: %s", running.cfg.modem_id, exc)
        try:
            thread.close()
        except Exception as exc:  # noqa: BLE001
            log.error("intervehicle link %d: closing its sockets failed: %s", running.cfg.modem_id, exc)

    def stop(self) -> None:
        if self._stopped:
            return
        self._stopped = True
        self._stopping.set()
        with self._lock:
            for running in self._running:
                running.thread.quit()
        for running in self._running:
            if running.pythread is not None:
                running.pythread.join(10)
