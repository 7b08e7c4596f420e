"""One loader for every extension point: gateway plugins, frontseat drivers, helm behaviours, the embedded helm.

Why one: python-can names its backends in a table and lets outsiders add more through an entry-point group; our
users also name things the Goby way (a library path in ``GOBY_MOOS_GATEWAY_PLUGINS`` or
``FRONTSEAT_DRIVER_LIBRARY``).  Each extension point is an :class:`ExtensionPoint`; :func:`load_extension`
turns a *spec* (what the user wrote) into the object it names, looking in this order:

1. an entry point of the point's group, by name.  A Goby shared-library file name (``lib<stem>.so[.N...]``,
   with or without a directory) stands for the entry point ``aliases[stem]``, else ``<stem>`` without the
   point's ``library_prefix``, else ``<stem>``.  Only entry points that are *named* are loaded: installing a
   package never adds an extension to a running program by itself;
2. a path to a Python file (the spec ends in ``.py`` or contains ``/``), imported under a private module name;
   the same file twice gives the same module;
3. a dotted module name, imported with :mod:`importlib`.

A point may accept entry points only (helm behaviours: a ``.bhv`` names a type, never a file).  Every failure
raises :class:`ExtensionError`, whose message names the kind of extension, the spec and the cause.  Loading runs
the imported module's top level on the calling thread; callers load before they start anything.
"""

from __future__ import annotations

import importlib
import importlib.util
import re
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType, ModuleType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import importlib.metadata

_SHARED_LIBRARY = re.compile(r"lib(?P<stem>.+?)\.so(?:\.[0-9.]*)?")


class ExtensionError(Exception):
    """An extension could not be found, imported or used; ``spec`` is what the user wrote, ``cause`` why."""

    def __init__(self, message: str, *, spec: str, cause: str) -> None:
        super().__init__(message)
        self.spec = spec
        self.cause = cause


@dataclass(frozen=True)
class ExtensionPoint:
    """One place third parties plug into.

    ``group``: the entry-point group; ``what``: the extension's name in messages (``"plugin"``, ``"frontseat
    driver library"``); ``source``: where specs are written (an environment variable, a file), for messages;
    ``aliases`` and ``library_prefix``: how Goby's shared-library names map to entry-point names;
    ``entry_points_only``: refuse file paths and dotted modules; ``builtin``: the project's own extensions, by
    entry-point name, as ``module`` or ``module:attribute`` (the same values as its entry points, which a test
    checks): found without reading package metadata, whose import costs 1.8-3.8 MiB in every process.
    """

    group: str
    what: str
    source: str = ""
    aliases: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))
    library_prefix: str = ""
    entry_points_only: bool = False
    builtin: Mapping[str, str] = field(default_factory=lambda: MappingProxyType({}))

    def entry_points(self) -> dict[str, importlib.metadata.EntryPoint]:
        """Installed entry points of the group, by name (read afresh: packages may be installed at run time).

        ``importlib.metadata`` is imported here, not at the top: it pulls the email package (1.8 MiB private) into
        every process, most of which never load an extension."""
        import importlib.metadata

        return {ep.name: ep for ep in importlib.metadata.entry_points(group=self.group)}

    def names(self) -> list[str]:
        """The names installed packages offer in this group, sorted."""
        return sorted(self.entry_points())

    def entry_point(self, spec: str) -> importlib.metadata.EntryPoint | None:
        """The entry point ``spec`` names (directly or through a Goby library name), or None."""
        installed = self.entry_points()
        for name in self._candidate_names(spec.strip()):
            if name in installed:
                return installed[name]
        return None

    def error(self, spec: str, cause: str) -> ExtensionError:
        """The one failure message: ``Failed to open <what>: <spec>, reason: <cause>`` (Goby's wording)."""
        return ExtensionError(f"Failed to open {self.what}: {spec or repr(spec)}, reason: {cause}", spec=spec,
                              cause=cause)

    def _candidate_names(self, spec: str) -> list[str]:
        match = _SHARED_LIBRARY.fullmatch(Path(spec).name)
        if match is None:
            return [spec]
        stem = match.group("stem")
        names = [self.aliases[stem]] if stem in self.aliases else []
        if self.library_prefix and stem.startswith(self.library_prefix):
            names.append(stem[len(self.library_prefix):])
        return [*names, stem]


def load_extension(point: ExtensionPoint, spec: str) -> Any:
    """The object ``spec`` names at ``point`` (a module for a file or dotted name; whatever an entry point names).

    Raises :class:`ExtensionError` naming the spec and the cause; the loaded module's own exceptions are
    reported as the cause, never escape.
    """
    spec = spec.strip()
    if not spec:
        where = f" in {point.source}" if point.source else ""
        raise point.error(spec, f"empty entry{where} (check for a leading, trailing or doubled delimiter)")
    for candidate in point._candidate_names(spec):
        target = point.builtin.get(candidate)
        if target is not None:
            return _load_builtin(point, spec, candidate, target)
    entry_point = point.entry_point(spec)
    if entry_point is not None:
        try:
            return entry_point.load()
        except Exception as exc:
            raise point.error(spec, f"entry point {entry_point.name} = {entry_point.value}: "
                                    f"{type(exc).__name__}: {exc}") from exc
    if point.entry_points_only:
        raise point.error(spec, f"no entry point of that name in group {point.group}{_known(point)}")
    if _SHARED_LIBRARY.fullmatch(Path(spec).name):
        raise point.error(spec, f"a shared library with no Python counterpart: no entry point "
                                f"{' or '.join(point._candidate_names(spec))} in group {point.group}{_known(point)}")
    if spec.endswith(".py") or "/" in spec:
        return _import_file(point, spec)
    try:
        return importlib.import_module(spec)
    except Exception as exc:
        name = exc.name if isinstance(exc, ModuleNotFoundError) else None
        missing = name is not None and (spec == name or spec.startswith(name + "."))  # the spec, not a dependency
        raise point.error(spec, f"{type(exc).__name__}: {exc}{_known(point) if missing else ''}") from exc


def _load_builtin(point: ExtensionPoint, spec: str, name: str, target: str) -> Any:
    """Import a built-in extension; a failure reads as its entry point's would (the table mirrors them)."""
    module_name, _, attribute = target.partition(":")
    try:
        loaded: Any = importlib.import_module(module_name)
        for part in filter(None, attribute.split(".")):
            loaded = getattr(loaded, part)
    except Exception as exc:
        raise point.error(spec, f"entry point {name} = {target}: {type(exc).__name__}: {exc}") from exc
    return loaded


def load_module(point: ExtensionPoint, spec: str) -> ModuleType:
    """:func:`load_extension` for points whose extensions are modules (an entry point must name a module)."""
    loaded = load_extension(point, spec)
    if not isinstance(loaded, ModuleType):
        raise point.error(spec, f"the entry point names {loaded!r}, not a module")
    return loaded


def module_function(point: ExtensionPoint, spec: str, module: ModuleType, name: str, *,
                    required: bool = True) -> Callable[..., Any] | None:
    """``module.<name>`` if callable; None if absent and optional; ExtensionError otherwise."""
    function = getattr(module, name, None)
    if function is None and not required:
        return None
    if not callable(function):
        state = "does not exist" if function is None else "is not callable"
        raise ExtensionError(f"Function {name} in {point.what}: {spec} {state} (module {module.__name__})",
                             spec=spec, cause=f"{name} {state}")
    return function


def _known(point: ExtensionPoint) -> str:
    names = point.names()
    return f" (entry points in {point.group}: {', '.join(names) if names else 'none'})"


def _import_file(point: ExtensionPoint, spec: str) -> ModuleType:
    path = Path(spec).expanduser()
    if not path.is_file():
        raise point.error(spec, "no such file")
    resolved = path.resolve()
    import hashlib  # here, not at the top: it loads OpenSSL (3.6 MiB of private memory in every process)

    digest = hashlib.sha1(str(resolved).encode()).hexdigest()[:10]
    name = f"_extension_{re.sub(r'[^0-9A-Za-z_]', '_', path.stem)}_{digest}"
    if name in sys.modules:  # the same file again: the same module, as a second dlopen gives the same handle
        return sys.modules[name]
    module_spec = importlib.util.spec_from_file_location(name, resolved)
    if module_spec is None or module_spec.loader is None:
        raise point.error(spec, "not a Python module")
    module = importlib.util.module_from_spec(module_spec)
    sys.modules[name] = module  # so dataclasses and pickling inside the module can find it
    try:
        module_spec.loader.exec_module(module)
    except BaseException as exc:
        del sys.modules[name]
        if not isinstance(exc, Exception):
            raise
        raise point.error(spec, f"{type(exc).__name__}: {exc}") from exc
    return module
