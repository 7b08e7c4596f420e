"""Goby3-style portal: groups, marshalling, wire identifiers, broker, interprocess/interthread transporters,
applications and threads, config loading, and the warped clock.  See docs/portal.md."""

from gateway.portal.application import MultiThreadApplication, SingleThreadApplication
from gateway.portal.context import ProcessContext, current_context, use_context
from gateway.portal.errors import (
    BrokerUnavailableError,
    ClosedError,
    ConfigError,
    IdentifierError,
    InvalidGroupError,
    MarshallingError,
    PortalError,
    ThreadError,
    WrongThreadError,
)
from gateway.portal.group import BROADCAST_GROUP, INVALID_NUMERIC_GROUP, Group
from gateway.portal.interface_registry import InterfaceEntry, InterfaceRegistry, process_registry
from gateway.portal.interprocess import InterProcessPortal
from gateway.portal.interthread import InterThread, InterThreadTransporter
from gateway.portal.marshalling import Scheme
from gateway.portal.runner import run_application
from gateway.portal.thread import SimpleThread
from gateway.portal.timeutil import SystemClock, clock

__all__ = [
    "BROADCAST_GROUP",
    "INVALID_NUMERIC_GROUP",
    "BrokerUnavailableError",
    "ClosedError",
    "ConfigError",
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
    "SystemClock",
    "ThreadError",
    "WrongThreadError",
    "clock",
    "current_context",
    "process_registry",
    "run_application",
    "use_context",
]
