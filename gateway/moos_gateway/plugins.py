"""Gateway plugins: the modules named in ``GOBY_MOOS_GATEWAY_PLUGINS``, each exposing ``load(gateway)``.

Why this shape: goby_moos_gateway ``dlopen``s the libraries listed in the variable and calls their
``goby3_moos_gateway_load``; we import Python modules instead, through the project's one extension loader
(``util.extensions``: an entry point of group ``goby_moos_gateway.plugins`` by name, a ``.py`` path, or a dotted
module).  The list is split on any of ``;``, ``:`` and ``,``, as Goby does.  Goby's library file name
``libgoby_ivp_frontseat_moos_gateway_plugin.so`` (with or without a directory) stands for our ``frontseat``,
``libgoby_coroner_moos_gateway_plugin.so`` for our ``coroner``.

Everything is resolved (imported, ``load`` found) before the gateway starts, so a bad entry stops the
process before anything runs; ``ExtensionError`` names the entry and the cause.
"""

from __future__ import annotations

import logging
import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType, ModuleType
from typing import Any

from util.extensions import ExtensionError, ExtensionPoint, load_module, module_function

log = logging.getLogger(__name__)

ENV_VAR = "GOBY_MOOS_GATEWAY_PLUGINS"
DELIMITERS = ";:,"

PLUGIN_POINT = ExtensionPoint(
    group="goby_moos_gateway.plugins",
    what="plugin",
    source=ENV_VAR,
    # Goby3's shared-library names for the plugins we re-implement (without "lib" and ".so...")
    aliases=MappingProxyType({"goby_ivp_frontseat_moos_gateway_plugin": "frontseat",
                              "goby_coroner_moos_gateway_plugin": "coroner",
                              "goby3_course_moos_gateway_plugin": "goby3_course"}),
    builtin=MappingProxyType({"frontseat": "translators.frontseat.translation",
                              "usv_command": "translators.usv.command_translation",
                              "node_report": "translators.node_report",
                              "coroner": "translators.coroner",
                              "goby3_course": "translators.trail.gateway_plugin"}),
)


@dataclass(frozen=True)
class Plugin:
    """One resolved plugin: the entry as written, its module, and its hooks."""

    entry: str
    module: ModuleType | None  # None for a plugin built in code (translators.testing.hosted_translators)
    load: Callable[[Any], None]
    unload: Callable[[Any], None] | None


def split_plugin_list(value: str) -> list[str]:
    """Split on any of ``;:,`` keeping empty entries, as Goby's ``boost::split`` does (they are errors later)."""
    return re.split(f"[{re.escape(DELIMITERS)}]", value)


def plugin_entries_from_env(environ: Mapping[str, str] | None = None) -> list[str]:
    """The entries of ``GOBY_MOOS_GATEWAY_PLUGINS``; ExtensionError if it is unset or empty."""
    value = (os.environ if environ is None else environ).get(ENV_VAR)
    if not value:
        raise ExtensionError(f"Must define at least one plugin library in {ENV_VAR} environmental variable",
                             spec="", cause=f"{ENV_VAR} is unset")
    return split_plugin_list(value)


def resolve_plugins(entries: list[str]) -> list[Plugin]:
    """Resolve every entry in order; the first failure raises ExtensionError (nothing is half-loaded).

    The same module named twice is an error, as in Goby (where the second ``launch_thread`` of a type throws).
    """
    plugins: list[Plugin] = []
    for entry in entries:
        plugin = resolve_plugin(entry)
        module = plugin.module
        for earlier in plugins:
            if module is not None and earlier.module is module:
                cause = f"module {module.__name__} is already loaded as {earlier.entry}"
                raise ExtensionError(f"plugin {entry}: {cause} (listed twice in {ENV_VAR})", spec=entry, cause=cause)
        plugins.append(plugin)
    return plugins


def resolve_plugin(entry: str) -> Plugin:
    """Import one entry and find its ``load`` (required) and ``unload`` (optional)."""
    log.info("Loading plugin library: %s", entry)
    module = load_module(PLUGIN_POINT, entry)
    load = module_function(PLUGIN_POINT, entry, module, "load")
    unload = module_function(PLUGIN_POINT, entry, module, "unload", required=False)
    assert load is not None
    return Plugin(entry, module, load, unload)
