"""Gateway plugins: the modules named in ``GOBY_MOOS_GATEWAY_PLUGINS``, each exposing ``load(gateway)``.

Why this shape: goby_moos_gateway ``dlopen``s the libraries listed in the variable and calls their
``goby3_moos_gateway_load``; we import Python modules instead.  Each entry of the list (split on any of
``;``, ``:`` and ``,``, as Goby does) is, in this order of precedence:

1. a path to a ``.py`` file (anything ending in ``.py`` or containing ``/``), imported under a private name;
2. the name of an entry point in the ``goby_moos_gateway.plugins`` group (``frontseat``, ``usv_command``,
   ``node_report`` ship with this package; installed packages can add more).  Only entry points that are
   *named* are loaded -- installing a package never adds a plugin to a gateway by itself.  Goby's library
   file names (``libgoby_ivp_frontseat_moos_gateway_plugin.so``, with or without a directory) are accepted as
   aliases of ours;
3. a dotted module name, imported with ``importlib``.

Everything is resolved (imported, ``load`` found) before the gateway starts, so a bad entry stops the
process before anything runs; ``PluginError`` names the entry and the cause.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.metadata
import importlib.util
import logging
import os
import re
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

log = logging.getLogger(__name__)

ENV_VAR = "GOBY_MOOS_GATEWAY_PLUGINS"
ENTRY_POINT_GROUP = "goby_moos_gateway.plugins"
DELIMITERS = ";:,"

# Goby3's shared-library names for the plugins we re-implement (basename without "lib" and ".so...").
GOBY_LIBRARY_ALIASES = {"goby_ivp_frontseat_moos_gateway_plugin": "frontseat"}


class PluginError(RuntimeError):
    """A plugin could not be found, imported, or has no ``load``; the message names the entry and why."""


@dataclass(frozen=True)
class Plugin:
    """One resolved plugin: the entry as written, its module, and its hooks."""

    entry: str
    module: ModuleType | None
    load: Callable[[Any], None]
    unload: Callable[[Any], None] | None


def split_plugin_list(value: str) -> list[str]:
    """Split on any of ``;:,`` keeping empty entries, as Goby's ``boost::split`` does (they are errors later)."""
    return re.split(f"[{re.escape(DELIMITERS)}]", value)


def plugin_entries_from_env(environ: Mapping[str, str] | None = None) -> list[str]:
    """The entries of ``GOBY_MOOS_GATEWAY_PLUGINS``; PluginError if it is unset or empty."""
    value = (os.environ if environ is None else environ).get(ENV_VAR)
    if not value:
        raise PluginError(f"Must define at least one plugin library in {ENV_VAR} environmental variable")
    return split_plugin_list(value)


def resolve_plugins(entries: list[str]) -> list[Plugin]:
    """Resolve every entry in order; the first failure raises PluginError (nothing is half-loaded).

    The same module named twice is an error, as in Goby (where the second ``launch_thread`` of a type throws).
    """
    plugins: list[Plugin] = []
    for entry in entries:
        plugin = resolve_plugin(entry)
        for earlier in plugins:
            if earlier.module is plugin.module:
                raise PluginError(f"plugin {entry}: module {plugin.module.__name__} is already loaded as "
                                  f"{earlier.entry} (listed twice in {ENV_VAR})")
        plugins.append(plugin)
    return plugins


def resolve_plugin(entry: str) -> Plugin:
    """Import one entry (file path, entry-point name, or dotted module) and find its ``load``/``unload``."""
    log.info("Loading plugin library: %s", entry)
    if not entry.strip():
        raise PluginError(f"Failed to open plugin: {entry!r}, reason: empty entry in {ENV_VAR} "
                          f"(check for a leading, trailing or doubled delimiter)")
    module = _import(entry.strip())
    load = getattr(module, "load", None)
    if not callable(load):
        raise PluginError(f"Function load in plugin: {entry} does not exist (module {module.__name__})")
    unload = getattr(module, "unload", None)
    if unload is not None and not callable(unload):
        raise PluginError(f"unload in plugin: {entry} is not callable")
    return Plugin(entry, module, load, unload)


def _import(entry: str) -> ModuleType:
    if _library_stem(Path(entry).name) in GOBY_LIBRARY_ALIASES:  # Goby's .so name, with or without a directory
        entry = Path(entry).name
    elif entry.endswith(".py") or "/" in entry:
        return _import_file(entry)
    entry_point = _entry_point(entry)
    if entry_point is not None:
        try:
            loaded = entry_point.load()
        except Exception as exc:
            raise PluginError(f"Failed to open plugin: {entry} (entry point {entry_point.value}), "
                              f"reason: {type(exc).__name__}: {exc}") from exc
        if not isinstance(loaded, ModuleType):
            raise PluginError(f"Entry point {entry} ({entry_point.value}) must name a module with load(gateway)")
        return loaded
    try:
        return importlib.import_module(entry)
    except Exception as exc:
        raise PluginError(f"Failed to open plugin: {entry}, reason: {type(exc).__name__}: {exc}") from exc


def entry_point_names() -> list[str]:
    """Names offered by installed packages in the ``goby_moos_gateway.plugins`` group."""
    return sorted(ep.name for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP))


def _entry_point(entry: str) -> importlib.metadata.EntryPoint | None:
    name = GOBY_LIBRARY_ALIASES.get(_library_stem(entry), entry)
    for entry_point in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        if entry_point.name == name:
            return entry_point
    return None


def _library_stem(entry: str) -> str:
    """``libfoo.so.3`` -> ``foo`` (Goby's plugin names), anything else unchanged."""
    match = re.fullmatch(r"lib(.+?)\.so(\.[0-9.]*)?", entry)
    return match.group(1) if match else entry


def _import_file(entry: str) -> ModuleType:
    path = Path(entry).expanduser()
    if not path.is_file():
        raise PluginError(f"Failed to open plugin: {entry}, reason: no such file")
    digest = hashlib.sha1(str(path.resolve()).encode()).hexdigest()[:10]
    name = f"goby_moos_gateway_plugin_{path.stem}_{digest}"
    if name in sys.modules:  # the same file again: the same module, as a second dlopen gives the same handle
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise PluginError(f"Failed to open plugin: {entry}, reason: not a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # so dataclasses/pickling inside the plugin can find their module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        del sys.modules[name]
        raise PluginError(f"Failed to open plugin: {entry}, reason: {type(exc).__name__}: {exc}") from exc
    return module
