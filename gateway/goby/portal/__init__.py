"""Goby3-style portal: groups, marshalling, wire identifiers, broker, interprocess/interthread transporters,
applications and threads, config loading, and the warped clock.  See docs/portal.md."""

from gateway.goby.portal.application import MultiThreadApplication, SingleThreadApplication
from gateway.goby.portal.context import ProcessContext, current_context, use_context
from gateway.goby.portal.errors import (
    AppConfigError,
    BrokerUnavailableError,
    ClosedError,
    IdentifierError,
    InvalidGroupError,
    MarshallingError,
    PortalError,
    StartError,
    ThreadError,
    WrongThreadError,
)
from gateway.goby.portal.group import BROADCAST_GROUP, INVALID_NUMERIC_GROUP, Group
from gateway.goby.portal.interface_registry import InterfaceEntry, InterfaceRegistry
from gateway.goby.portal.interprocess import InterProcessPortal
from gateway.goby.portal.interthread import InterThread, InterThreadTransporter
from gateway.goby.portal.marshalling import Scheme
from gateway.goby.portal.runner import run_application
from gateway.goby.portal.thread import SimpleThread
from gateway.goby.portal.timeutil import SystemClock

__all__ = [
    "BROADCAST_GROUP",
    "INVALID_NUMERIC_GROUP",
    "BrokerUnavailableError",
    "ClosedError",
    "AppConfigError",
    "Group",
    "IdentifierError",
    "InterProcessPortal",
    "InterThread",
    "InterThreadTransporter",
    "InterfaceEntry",
    "InterfaceRegistry",
    "InvalidGroupError",
    "MarshallingError",
    "MultiThreadApplication",
    "PortalError",
    "ProcessContext",
    "Scheme",
    "SimpleThread",
    "SingleThreadApplication",
    "StartError",
    "SystemClock",
    "ThreadError",
    "WrongThreadError",
    "current_context",
    "run_application",
    "use_context",
]
