"""Check interface files against what applications actually did: the proof that the two cannot drift apart.

Applications record every publish/subscribe call in the portal's registry (``GOBY_INTERFACE_REGISTRY``);
this module compares those records with the statically derived interfaces. Every call made at run time must be
in the interface of the thread that made it, and every subscription in an interface must have been made
(subscriptions happen at start-up; a publication may legitimately not occur in a given run).
"""

from __future__ import annotations

from collections.abc import Iterable

from gateway.goby.portal.interface_registry import InterfaceEntry
from launch.interfaces.model import ApplicationInterface

INTERNAL_GROUP_PREFIXES = ("goby::zeromq::_internal", "goby::middleware::interprocess::",
                           "goby::middleware::intervehicle::")  # transport internals (intervehicle diagnostics)
_DIRECTION = {"publish": "publishes", "subscribe": "subscribes"}


def _key(direction: str, group: str, scheme: str, type_name: str) -> tuple[str, str, str, str]:
    return direction, group, scheme, type_name


def _cxx(type_name: str) -> str:
    return type_name.replace(".", "::")


def drift_problems(runtime: Iterable[InterfaceEntry], interfaces: Iterable[ApplicationInterface]) -> list[str]:
    """Differences between run-time records and static interfaces (interprocess layer), as readable lines.

    Threads are matched by class name (the registry records ``__qualname__``, interface files ``module.Class``);
    only threads that appear in both are compared, so one run can cover any subset of the applications.
    """
    static: dict[str, set[tuple[str, str, str, str]]] = {}
    for interface in interfaces:
        for entry in interface.entries:
            if entry.layer == "interprocess" and not entry.inner:
                key = _key(entry.direction, entry.group, entry.scheme, entry.type)
                static.setdefault(entry.thread.rsplit(".", 1)[-1], set()).add(key)
    seen: dict[str, set[tuple[str, str, str, str]]] = {}
    # (group, type) a thread subscribed by interthread: a thread may take a group from a publisher in its own
    # process by interthread instead of interprocess (the embedded FrontSeatTranslation and the interface)
    local: dict[str, set[tuple[str, str]]] = {}
    for record in runtime:
        if record.layer == "interthread" and record.direction == "subscribe":
            local.setdefault(record.thread, set()).add((record.group, _cxx(record.type)))
        if record.layer != "interprocess" or record.group.startswith(INTERNAL_GROUP_PREFIXES):
            continue
        seen.setdefault(record.thread, set()).add(
            _key(_DIRECTION[record.direction], record.group, record.scheme, _cxx(record.type))
        )
    problems = []
    for thread in sorted(static.keys() & seen.keys()):
        for key in sorted(seen[thread] - static[thread]):
            problems.append(f"{thread}: made at run time but missing from its interface file: {key}")
        for key in sorted(k for k in static[thread] - seen[thread] if k[0] == "subscribes"):
            if (key[1], key[3]) not in local.get(thread, set()):
                problems.append(f"{thread}: in its interface file but never subscribed at run time: {key}")
    return problems


def covered_threads(runtime: Iterable[InterfaceEntry], interfaces: Iterable[ApplicationInterface]) -> set[str]:
    """Thread class names present both in the run-time records and in the interface files."""
    static = {e.thread.rsplit(".", 1)[-1] for i in interfaces for e in i.entries}
    return static & {r.thread for r in runtime}
