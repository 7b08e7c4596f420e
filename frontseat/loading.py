"""Finding the driver named by ``FRONTSEAT_DRIVER_LIBRARY`` (python-can's backend registry, our way).

The variable may name, in this order of lookup:

1. an entry point of group ``goby_frontseat.drivers`` (``basic_simulator``), or Goby's library file name
   for it (``libgoby_frontseat_basic_simulator.so.30``), so Goby-style launch files keep working;
2. a Python file (``/path/to/my_driver.py``);
3. a dotted module (``frontseat.basic_simulator_driver``).

The module must define ``frontseat_driver_load(cfg) -> FrontSeatDriver`` and may define
``CONFIG_EXTENSION`` (the driver's ``Config`` extension field, used for ``--example_config``). Importing the
module registers its config extension, one driver per process, which keeps clashing extension numbers
(1001: basic simulator and Waveglider) apart.
"""

from __future__ import annotations

import importlib
import importlib.util
import re
import sys
from collections.abc import Callable
from importlib.metadata import entry_points
from pathlib import Path
from types import ModuleType

from frontseat.driver import FrontSeatDriver
from frontseat.errors import DriverLoadError
from frontseat.protobuf import frontseat_config_pb2 as config_pb

ENV_VAR = "FRONTSEAT_DRIVER_LIBRARY"
ENTRY_POINT_GROUP = "goby_frontseat.drivers"
FACTORY_NAME = "frontseat_driver_load"

DriverFactory = Callable[[config_pb.Config], FrontSeatDriver]

_GOBY_LIBRARY = re.compile(r"^lib(?:goby_frontseat_)?(?P<name>\w+?)\.so(?:\.\d+)*$")


def available_drivers() -> dict[str, str]:
    """Installed driver entry points: name -> module."""
    return {ep.name: ep.value for ep in entry_points(group=ENTRY_POINT_GROUP)}


def load_driver_library(spec: str) -> ModuleType:
    """Import the driver module ``spec`` names. Raises :class:`DriverLoadError` naming ``spec`` and the cause."""
    spec = spec.strip()
    if not spec:
        raise DriverLoadError(f"{ENV_VAR} is empty; set it to a driver name, module or .py file")
    registered = {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}
    goby_name = _GOBY_LIBRARY.match(Path(spec).name)
    name = spec if spec in registered else goby_name.group("name") if goby_name else None
    try:
        if name in registered:
            module = registered[name].load()
            if not isinstance(module, ModuleType):
                raise TypeError(f"entry point {name!r} names {module!r}, not a module")
            return module
        if spec.endswith(".py") or "/" in spec:
            return _load_file(Path(spec))
        return importlib.import_module(spec)
    except DriverLoadError:
        raise
    except Exception as exc:
        known = ", ".join(sorted(registered)) or "none"
        raise DriverLoadError(
            f"failed to open frontseat driver library {spec!r}: {type(exc).__name__}: {exc} "
            f"(installed drivers: {known})"
        ) from exc


def _load_file(path: Path) -> ModuleType:
    if not path.is_file():
        raise FileNotFoundError(f"no such file {path}")
    module_name = "_frontseat_driver_" + re.sub(r"\W", "_", str(path.resolve()))
    if module_name in sys.modules:
        return sys.modules[module_name]
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot import {path}")
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[module_name]
        raise
    return module


def driver_factory(module: ModuleType, spec: str | None = None) -> DriverFactory:
    """The module's ``frontseat_driver_load``; :class:`DriverLoadError` if it has none."""
    factory = getattr(module, FACTORY_NAME, None)
    if not callable(factory):
        raise DriverLoadError(
            f"function {FACTORY_NAME} in the library defined in {ENV_VAR} ({spec or module.__name__}) does not exist"
        )

    def checked(cfg: config_pb.Config) -> FrontSeatDriver:
        driver = factory(cfg)
        if not isinstance(driver, FrontSeatDriver):
            raise DriverLoadError(
                f"{FACTORY_NAME} in {spec or module.__name__} returned {driver!r}, not a FrontSeatDriver"
            )
        return driver

    return checked


def load_driver(spec: str, cfg: config_pb.Config) -> FrontSeatDriver:
    """Load the library ``spec`` and build its driver with ``cfg``."""
    return driver_factory(load_driver_library(spec), spec)(cfg)
