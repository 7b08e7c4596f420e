"""goby-liaison's application: the portal thread that joins the platform's broker, and the web server it starts.

Threads: the application's main thread is the portal thread (a ``SingleThreadApplication``): its regex
subscription stores every publication in the scope and map models, and it publishes the commands the web thread
hands over through ``call_soon``.  It never waits for the web side: outcomes go back with
``WebServer.call`` (non-blocking).  The web server runs on its own thread (``server.WebServer``).
"""

from __future__ import annotations

import logging
from typing import Any

from google.protobuf import text_format
from google.protobuf.message import Message

from gateway.goby.intervehicle import AckData, ExpireData, Publisher
from gateway.goby.portal import SingleThreadApplication, StartError
from gateway.goby.portal.errors import ClosedError
from gateway.goby.portal.group import Group
from gateway.goby.portal.marshalling import Scheme
from gateway.goby.protobuf.layer_pb2 import LAYER_INTERTHREAD, LAYER_INTERVEHICLE
from gateway.moos.client import comms
from launch.liaison.commander_model import CommanderModel, CommandType, Target
from launch.liaison.errors import LiaisonError
from launch.liaison.map_model import (
    HEALTH_STATUS_TYPE,
    HELM_VARIABLES,
    NAV_REPORT_TYPE,
    NODE_STATUS_TYPE,
    USV_COMMAND_TYPE,
    MapModel,
)
from launch.liaison.message_types import find_message_type
from launch.liaison.protobuf.liaison_config_pb2 import LiaisonConfig
from launch.liaison.protobuf.liaison_web_pb2 import InterProcessAck
from launch.liaison.scope_model import ScopeModel
from launch.liaison.server import WebServer
from launch.liaison.settings import LiaisonSettings, MoosEndpoint, load_settings

log = logging.getLogger(__name__)

READY_PREFIX = "goby-liaison ready:"


class LiaisonApp(SingleThreadApplication):
    """One platform's web page: scope, commander and map, fed by one regex subscription on the broker."""

    def __init__(self, cfg: LiaisonConfig, settings: LiaisonSettings | None = None) -> None:
        try:  # before joining the broker: a config error is named even when no broker runs
            s = settings or load_settings(cfg)
        except LiaisonError as exc:
            raise StartError(f"goby-liaison: {exc}") from exc
        super().__init__(cfg, loop_frequency_hz=1.0)
        self.settings = s
        self.scope = ScopeModel(s.max_history, s.max_rows, s.max_message_size)
        clock = self.context.clock
        self.map = MapModel(s.waypoints, s.polygon, s.center_activate, s.trail_points, clock.now,
                            initial_mode=s.initial_mode, datum=s.datum, helm_views=s.moos is not None,
                            background=s.background)
        self._moos: Any = None
        self.commander = CommanderModel(s.command_types, s.command_history)
        self.web = WebServer(s, self.scope, self.commander, self.map, self._hand_over, clock.now)
        portal = self.interprocess()
        portal.subscribe_regex(self._on_publication, ".*", ".*", (Scheme.ALL_SCHEMES,))
        for kind in s.command_types:
            if kind.ack is not None:
                self._subscribe_ack(kind.ack)
        if s.moos is not None:
            self._read_helm(s.moos)
        try:
            self.web.start()
        except LiaisonError as exc:
            raise StartError(f"goby-liaison: {exc}") from exc
        urls = self.web.urls
        print(f"{READY_PREFIX} {urls['home']} (scope {urls['scope']}, commander {urls['commander']}, "
              f"map {urls['map']})", flush=True)

    # ------------------------------------------------------------------------------- portal thread
    def _on_publication(self, payload: bytes, scheme: int, type_name: str, group: str) -> None:
        """Every publication on the broker. Runs on the portal thread: store, never decode or wait."""
        now = self.context.clock.now()
        self.scope.ingest(group, scheme, type_name, payload, now)
        if scheme == Scheme.PROTOBUF:
            if type_name == NODE_STATUS_TYPE:
                self.map.ingest_node_status(group, payload)
            elif type_name == USV_COMMAND_TYPE:
                self.map.ingest_command(payload)
            elif type_name == HEALTH_STATUS_TYPE:
                self.map.ingest_health(payload)
            elif type_name == NAV_REPORT_TYPE:
                self.map.ingest_nav_report(group, payload)

    def _read_helm(self, endpoint: MoosEndpoint) -> None:
        """Read the helm's VIEW_* and DEPLOY_STATE from the vehicle's MOOSDB, as pMarineViewer does: a MOOS client
        on this thread's reactor (no thread of its own); it reconnects by itself if the MOOSDB is not up yet."""
        client = comms(reactor=self.reactor)

        def on_connect() -> bool:
            for variable in HELM_VARIABLES:
                client.register(variable, 0)
            return True

        def on_mail() -> bool:
            for msg in client.fetch():
                if msg.is_string():
                    self.map.ingest_moos(msg.key(), msg.string())
            return True

        client.set_on_connect_callback(on_connect)
        client.set_on_mail_callback(on_mail)
        client.run(endpoint.host, endpoint.port, endpoint.name)
        self._moos = client
        log.info("reading the helm's %s from the MOOSDB at %s:%d", ", ".join(HELM_VARIABLES), endpoint.host,
                 endpoint.port)

    def _subscribe_ack(self, rule: InterProcessAck) -> None:
        ack_cls = find_message_type(rule.ack_type)
        finals = set(rule.final_value)

        def on_ack(ack: Message) -> None:
            """An ack message for commands of ``rule.command_type``. Runs on the portal thread."""
            value = getattr(ack, rule.ack_field)
            state = _field_text(ack, rule.final_field) if rule.HasField("final_field") else ""
            final = not rule.HasField("final_field") or state in finals
            refused = bool(rule.refused_value) and state == rule.refused_value
            text = text_format.MessageToString(ack, as_one_line=True)
            self.web.call(self.web.interprocess_ack, rule.command_type, value, text, final or refused, refused)

        self.interprocess().subscribe(rule.ack_group, ack_cls, on_ack)

    def _publish(self, kind: CommandType, target: Target, msg: Message, entry_id: int) -> None:
        """Publish one command. Runs on the portal thread (handed over by ``_hand_over``)."""
        try:
            group = target.group_for(msg)
            if target.layer == LAYER_INTERTHREAD:
                self.interthread().publish(group, msg)
            elif target.layer == LAYER_INTERVEHICLE:
                self.intervehicle().publish(group, msg, publisher=self._intervehicle_publisher(target, entry_id))
            else:
                self.interprocess().publish(group, msg)
        except Exception as exc:  # noqa: BLE001 - reported to the page that sent it
            log.error("could not publish %s to %s: %s", kind.name, target.label, exc)
            self.web.call(self.web.command_published, entry_id, f"{type(exc).__name__}: {exc}")
            return
        log.info("sent %s to %s: %s", kind.name, target.label, text_format.MessageToString(msg, as_one_line=True))
        self.web.call(self.web.command_published, entry_id, None)

    def _intervehicle_publisher(self, target: Target, entry_id: int) -> Publisher:
        """Goby's commander publisher: ``set_group`` writes the numeric group into ``group_numeric_field_name``
        (if configured), and the ack/expire callbacks (which make the link require an ack) report to the page's
        history as ``Ack: ...`` / ``Expire: ...``. The callbacks run on the portal thread."""

        def set_group(msg: Message, group: Group) -> None:
            if target.numeric_field:
                setattr(msg, target.numeric_field, group.numeric)

        def on_ack(_msg: Message, ack: AckData) -> None:
            text = f"Ack: {text_format.MessageToString(ack, as_one_line=True)}"
            self.web.call(self.web.command_acknowledged, entry_id, text)

        def on_expire(_msg: Message, expire: ExpireData) -> None:
            text = f"Expire: {text_format.MessageToString(expire, as_one_line=True)}"
            self.web.call(self.web.command_expired, entry_id, text)

        return Publisher(set_group=set_group, on_ack=on_ack, on_expire=on_expire)

    # ---------------------------------------------------------------------------------- web thread
    def _hand_over(self, kind: CommandType, target: Target, msg: Message, entry_id: int) -> None:
        """Queue a command for the portal thread. Runs on the web thread; never blocks."""
        try:
            self.call_soon(lambda: self._publish(kind, target, msg, entry_id))
        except ClosedError as exc:
            self.web.command_published(entry_id, f"not sent: {exc}")

    def finalize(self) -> None:
        self.web.stop()

    def close(self) -> None:
        if self._moos is not None:
            self._moos.close()
            self._moos = None
        self.web.stop()
        super().close()


def _field_text(msg: Message, name: str) -> Any:
    """An enum field by its value name, anything else as str."""
    field = msg.DESCRIPTOR.fields_by_name[name]
    value = getattr(msg, name)
    if field.enum_type is not None:
        return field.enum_type.values_by_number[value].name if value in field.enum_type.values_by_number else str(
            value)
    return str(value)
