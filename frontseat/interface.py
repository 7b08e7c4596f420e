"""The goby_frontseat_interface application (console script ``frontseat-interface``, ``frontseat.apps.frontseat_interface``).

It loads one driver (``FRONTSEAT_DRIVER_LIBRARY``), whose I/O runs on the main thread's reactor, ticks it at
10 Hz times warp (Goby's loop: the state machine and the driver's timeouts), and bridges it to the portal with
Goby's groups and state gating: commands reach the frontseat only in COMMAND, data and raw in LISTEN or COMMAND.
Data does not wait for the tick: a fix the driver reads is published as it arrives. Status goes out every
``status_period`` (simulated) seconds. With a ``[goby.moos.protobuf.moos_helm]`` block it also runs the MOOS helm
interface thread (found by entry point ``moos_helm``: the translators' FrontSeatTranslation), which connects
pHelmIvP (or any MOOS helm) through a MOOSDB; as Goby's threads, it takes ``node_status`` from this thread and gives
``helm_state``/``desired_course`` to it by interthread (all three are still published interprocess, as in Goby), and
this thread then takes those two from it only.

Threading: every subscription callback, the driver's signals and the driver itself run on the main thread.
"""

from __future__ import annotations

import logging

from frontseat import groups
from frontseat.driver import FrontSeatDriver, hosted_on
from frontseat.errors import FrontSeatException
from frontseat.loading import DriverFactory, helm_interface_class
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from frontseat.protobuf import frontseat_data_pb2 as data_pb
from frontseat.protobuf import frontseat_interface_config_pb2 as app_pb
from frontseat.protobuf import frontseat_pb2 as fs_pb
from frontseat.protobuf import moos_helm_frontseat_interface_config_pb2 as helm_pb
from frontseat.protobuf import navigation_pb2 as nav_pb
from gateway.goby.portal import MultiThreadApplication, use_context
from gateway.moos_gateway.protobuf import moos_gateway_config_pb2 as gateway_pb
from util.descriptors import message_type_of

log = logging.getLogger(__name__)

LOOP_FREQUENCY_HZ = 10.0
_ERROR_STATES = (fs_pb.INTERFACE_HELM_ERROR, fs_pb.INTERFACE_FS_ERROR)


def driver_config(cfg: app_pb.FrontSeatInterfaceConfig) -> config_pb.Config:
    """``frontseat_cfg`` completed as Goby does: name = platform, origin = app.geodesy, warp from sim time."""
    out = config_pb.Config()
    out.CopyFrom(cfg.frontseat_cfg)
    out.name = cfg.interprocess.platform
    out.origin.lat = cfg.app.geodesy.lat_origin  # an absent geodesy block reads as (0, 0), as in Goby
    out.origin.lon = cfg.app.geodesy.lon_origin
    if cfg.app.simulation.time.use_sim_time:
        out.sim_warp_factor = cfg.app.simulation.time.warp_factor
    return out


def helm_gateway_config(cfg: app_pb.FrontSeatInterfaceConfig) -> gateway_pb.GobyMOOSGatewayConfig | None:
    """The FrontSeatTranslation thread's config {app, interprocess, moos = moos_helm}, or None without moos_helm."""
    if not cfg.HasExtension(helm_pb.moos_helm):
        return None
    gateway_cfg = gateway_pb.GobyMOOSGatewayConfig()
    gateway_cfg.app.CopyFrom(cfg.app)
    gateway_cfg.interprocess.CopyFrom(cfg.interprocess)
    gateway_cfg.moos.CopyFrom(cfg.Extensions[helm_pb.moos_helm])
    return gateway_cfg


class FrontSeatInterface(MultiThreadApplication):
    """The interface application: one driver, the portal, and optionally the MOOS helm thread."""

    def __init__(self, cfg: app_pb.FrontSeatInterfaceConfig, driver_factory: DriverFactory, *,
                 loop_frequency_hz: float = LOOP_FREQUENCY_HZ) -> None:
        """``loop_frequency_hz`` (times warp) is Goby's 10 Hz; tests slow it to show that data does not wait for it."""
        super().__init__(cfg, loop_frequency_hz)
        self._next_status: float | None = None
        self._last_failure = ""
        self._last_helm_report: float | None = None
        self._helm_embedded = helm_gateway_config(cfg) is not None
        try:
            # the driver's default clock is this application's clock; its I/O runs on this thread's reactor
            with use_context(self.context), hosted_on(self.reactor):
                self._driver: FrontSeatDriver = driver_factory(driver_config(cfg))
            self._connect_driver()
            self._subscribe()
            self._launch_helm_interface()
        except BaseException:
            self.close()  # nobody else will: the caller never gets the object
            raise

    @property
    def driver(self) -> FrontSeatDriver:
        return self._driver

    # ----- wiring -----------------------------------------------------------------------------------------
    def _connect_driver(self) -> None:
        self._driver.signal_command_response.connect(self._on_command_response)
        self._driver.signal_data_from_frontseat.connect(self._on_data_from_frontseat)
        self._driver.signal_raw_from_frontseat.connect(self._on_raw_from_frontseat)
        self._driver.signal_raw_to_frontseat.connect(self._on_raw_to_frontseat)

    # ----- driver signals (main thread: in do_work, or as the driver's I/O arrives) ------------------------
    def _on_command_response(self, response: fs_pb.CommandResponse) -> None:
        self.interprocess().publish(groups.command_response, response)

    def _on_data_from_frontseat(self, data: fs_pb.InterfaceData) -> None:
        self.interprocess().publish(groups.data_from_frontseat, data)
        if data.HasField("node_status"):
            node_status: data_pb.NodeStatus = data.node_status
            self.interprocess().publish(groups.node_status, node_status)

    def _on_raw_from_frontseat(self, raw: fs_pb.Raw) -> None:
        self.interprocess().publish(groups.raw_in, raw)

    def _on_raw_to_frontseat(self, raw: fs_pb.Raw) -> None:
        self.interprocess().publish(groups.raw_out, raw)

    def _subscribe(self) -> None:
        portal = self.interprocess()
        # The helm's reports and setpoints: from the embedded MOOS helm interface thread by interthread (they never
        # leave the process to come back; it still publishes them interprocess for other processes, as in Goby),
        # else from whichever process runs the helm, through the broker.
        if self._helm_embedded:
            self.interthread().subscribe(groups.helm_state, fs_pb.HelmStateReport, self._on_helm_state)
            self.interthread().subscribe(groups.desired_course, data_pb.DesiredCourse, self._on_desired_course)
        else:
            portal.subscribe(groups.helm_state, fs_pb.HelmStateReport, self._on_helm_state)
            portal.subscribe(groups.desired_course, data_pb.DesiredCourse, self._on_desired_course)
        portal.subscribe(groups.command_request, fs_pb.CommandRequest, self._on_command_request)
        portal.subscribe(groups.data_to_frontseat, fs_pb.InterfaceData, self._on_data_to_frontseat)
        portal.subscribe(groups.raw_send_request, fs_pb.Raw, self._on_raw_send_request)
        portal.subscribe(groups.datum_update, nav_pb.DatumUpdate, self._on_datum_update)

    def _launch_helm_interface(self) -> None:
        gateway_cfg = helm_gateway_config(self.cfg())
        if gateway_cfg is None:
            return
        helm_interface = helm_interface_class()  # ExtensionError if not installed: one line, exit 1
        log.info("launching the MOOS helm interface thread %s (MOOSDB %s:%d)", helm_interface.__qualname__,
                 gateway_cfg.moos.server, gateway_cfg.moos.port)
        self.launch_thread(helm_interface, gateway_cfg, embedded=True)

    # ----- subscriptions (main thread) -------------------------------------------------------------------
    def _on_helm_state(self, report: fs_pb.HelmStateReport) -> None:
        self._driver.set_helm_state(report.state)
        self._last_helm_report = self._driver.now()

    def _on_command_request(self, command: fs_pb.CommandRequest) -> None:
        if self._driver.state() != fs_pb.INTERFACE_COMMAND:
            log.debug("not sending command because the interface is not in the command state")
            return
        self._driver.send_command_to_frontseat(command)

    def _on_desired_course(self, course: data_pb.DesiredCourse) -> None:
        if self._driver.state() != fs_pb.INTERFACE_COMMAND:
            log.debug("not sending desired course because the interface is not in the command state")
            return
        command = fs_pb.CommandRequest()
        command.desired_course.CopyFrom(course)
        self._driver.send_command_to_frontseat(command)

    def _on_data_to_frontseat(self, data: fs_pb.InterfaceData) -> None:
        if self._driver.state() not in (fs_pb.INTERFACE_COMMAND, fs_pb.INTERFACE_LISTEN):
            log.debug("not sending data because the interface is not in the command or listen state")
            return
        self._driver.send_data_to_frontseat(data)

    def _on_raw_send_request(self, raw: fs_pb.Raw) -> None:
        if self._driver.state() not in (fs_pb.INTERFACE_COMMAND, fs_pb.INTERFACE_LISTEN):
            log.debug("not sending raw because the interface is not in the command or listen state")
            return
        self._driver.send_raw_to_frontseat(raw)

    def _on_datum_update(self, update: nav_pb.DatumUpdate) -> None:
        try:
            self._driver.update_utm_datum(update.datum)
            log.info("UTM datum moved to (%f, %f)", update.datum.lat, update.datum.lon)
        except FrontSeatException as exc:
            log.error("ignoring datum update: %s", exc)

    # ----- the tick ---------------------------------------------------------------------------------------
    def loop(self) -> None:
        self._expire_helm_state()
        try:
            self._driver.do_work()
        except Exception as exc:
            # A driver bug, not a frontseat condition: report it (once per distinct failure) and keep serving.
            text = f"{type(exc).__name__}: {exc}"
            if text != self._last_failure:
                log.exception("the frontseat driver failed in do_work(); continuing")
            self._last_failure = text
        frontseat_cfg = self.cfg().frontseat_cfg
        if frontseat_cfg.exit_on_error and self._driver.state() in _ERROR_STATES:
            log.warning("error state detected (%s) and exit_on_error is true, so quitting",
                        fs_pb.InterfaceState.Name(self._driver.state()))
            self.quit(0)
            return
        self._publish_status_if_due(frontseat_cfg.status_period)

    def _expire_helm_state(self) -> None:
        """A helm that stopped reporting is a helm that is not running (Goby keeps the last report forever)."""
        timeout = self.cfg().frontseat_cfg.helm_running_timeout
        if (
            self._last_helm_report is not None
            and self._driver.helm_state() != fs_pb.HELM_NOT_RUNNING
            and self._driver.now() > self._last_helm_report + timeout
        ):
            log.warning("no helm_state report for %.1f s; treating the helm as not running", timeout)
            self._driver.set_helm_state(fs_pb.HELM_NOT_RUNNING)

    def _publish_status_if_due(self, period: float) -> None:
        now = self._driver.now()
        if self._next_status is not None and now < self._next_status:
            return
        self._next_status = now + period if self._next_status is None else max(self._next_status + period, now)
        status: fs_pb.InterfaceStatus = self._driver.status()
        log.debug("status: %s", status)
        self.interprocess().publish(groups.status, status)

    def close(self) -> None:
        """Close the driver (its sockets leave this thread's reactor), join the helm thread, close the portal;
        idempotent."""
        driver = getattr(self, "_driver", None)  # absent if the driver factory raised
        try:
            if driver is not None:
                driver.close()
        finally:
            super().close()


def example_config(driver_module: object | None = None) -> str:
    """A commented example configuration, with the driver's extension block when it declares one."""
    from gateway.goby.portal.config import example_config as message_example

    fields = app_pb.FrontSeatInterfaceConfig.DESCRIPTOR.fields_by_name
    app_body = message_example(message_type_of(fields["app"]), 1)
    interprocess_body = message_example(message_type_of(fields["interprocess"]), 1)
    frontseat_body = message_example(config_pb.Config.DESCRIPTOR, 1)
    extension = getattr(driver_module, "CONFIG_EXTENSION", None)
    if extension is not None:
        driver_body = message_example(extension.message_type, 2)
        frontseat_body += f"\n  [{extension.full_name}] {{  # the driver's settings\n{driver_body}\n  }}"
    tuning = getattr(driver_module, "TUNING_EXTENSION", None)
    if tuning is not None:  # a project extension: commented out, so the example stays a Goby3 config
        tuning_body = "\n".join("  #" + line[1:] for line in message_example(tuning.message_type, 2).splitlines())
        frontseat_body += (f"\n  # [{tuning.full_name}] {{  # our driver's own settings (not in Goby3)\n"
                           f"{tuning_body}\n  # }}")
    helm_body = message_example(gateway_pb.GobyMOOSGatewayConfig.MOOSConfig.DESCRIPTOR, 1)
    helm_body = "\n".join(f"# {line}" for line in helm_body.splitlines())
    return (
        f"app {{\n{app_body}\n}}\n"
        f"interprocess {{\n{interprocess_body}\n}}\n"
        f"frontseat_cfg {{  # name and origin are set from interprocess.platform and app.geodesy\n{frontseat_body}\n}}\n"
        "# [goby.moos.protobuf.moos_helm] {  # run the MOOS helm interface (FrontSeatTranslation) thread\n"
        f"{helm_body}\n# }}"
    )
