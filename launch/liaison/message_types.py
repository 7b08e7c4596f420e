"""Naming protobuf types by full name: import the modules that define them, then ask the symbol database.

Goby's liaison loads compiled types from shared libraries (``load_shared_library``); here a type can be named once
its generated ``_pb2`` module has been imported.  :func:`import_project_protos` imports every ``_pb2`` module of
this project, and :func:`load_message_modules` imports what a config names: an entry point of the
``goby_liaison.protobuf`` group (a Goby library name such as ``libgoby3_course_messages.so`` finds the entry point
``goby3_course_messages``), a Python file, or a dotted module name (one loader: ``util.extensions``).
"""

from __future__ import annotations

import importlib
import logging
import pkgutil
from collections.abc import Iterable

from google.protobuf import message as pb_message

from gateway.goby.portal.marshalling import message_class
from launch.liaison.errors import LiaisonConfigError
from util.extensions import ExtensionError, ExtensionPoint, load_extension

log = logging.getLogger(__name__)

MESSAGES_POINT = ExtensionPoint(
    group="goby_liaison.protobuf", what="protobuf message library", source="load_shared_library / load_python_module"
)
PROJECT_PACKAGES = ("gateway", "frontseat", "translators", "behaviors", "launch")


def import_project_protos(packages: Iterable[str] = PROJECT_PACKAGES) -> int:
    """Import every generated ``*_pb2`` module under ``packages``; returns how many were imported.

    A module that fails to import is logged and skipped: the types it defines then show as unknown.
    """
    count = 0
    for top in packages:
        package = importlib.import_module(top)
        for info in pkgutil.walk_packages(package.__path__, prefix=f"{top}.", onerror=lambda _name: None):
            if not info.name.endswith("_pb2"):
                continue
            try:
                importlib.import_module(info.name)
                count += 1
            except Exception as exc:  # noqa: BLE001 - one broken module must not hide the others
                log.warning("cannot import %s: %s", info.name, exc)
    return count


def load_message_modules(specs: Iterable[str]) -> None:
    """Import each module a config names; LiaisonConfigError names the spec and the cause."""
    for spec in specs:
        try:
            load_extension(MESSAGES_POINT, spec)
        except ExtensionError as exc:
            raise LiaisonConfigError(str(exc)) from exc


def find_message_type(full_name: str) -> type[pb_message.Message]:
    """The generated class of ``full_name``; LiaisonConfigError if no imported module defines it."""
    cls = message_class(full_name)
    if cls is None:
        raise LiaisonConfigError(
            f"protobuf type {full_name!r} is not known: name the Python module that defines it in "
            "load_shared_library or [goby_moos_py.liaison.protobuf.web] { load_python_module: ... }"
        )
    return cls
