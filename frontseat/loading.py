"""The frontseat's two extension points, both found through the project's one loader (``util.extensions``).

``FRONTSEAT_DRIVER_LIBRARY`` names the driver: an entry point of group ``goby_frontseat.drivers``
(``basic_simulator``), Goby's library file name for it (``libgoby_frontseat_basic_simulator.so.30``), a Python
file, or a dotted module.  The module must define ``frontseat_driver_load(cfg) -> FrontSeatDriver`` and may define
``CONFIG_EXTENSION`` (the driver's ``Config`` extension field, used for ``--example_config``) and
``TUNING_EXTENSION`` (a project extension with settings Goby's driver hard-codes, shown commented out). Importing the
module registers its config extension, one driver per process, which keeps clashing extension numbers
(1001: basic simulator and Waveglider) apart.

A ``[goby.moos.protobuf.moos_helm]`` block runs the MOOS helm interface thread, found as the entry point
``moos_helm`` of group ``goby_frontseat.helm_interfaces`` (this project's ``FrontSeatTranslation``), so the
frontseat tree needs no import of the translators built on top of it.
"""

from __future__ import annotations

from collections.abc import Callable
from types import MappingProxyType, ModuleType

from frontseat.driver import FrontSeatDriver
from frontseat.protobuf import frontseat_config_pb2 as config_pb
from gateway.goby.portal import SimpleThread
from util.extensions import ExtensionPoint, load_extension, load_module, module_function

ENV_VAR = "FRONTSEAT_DRIVER_LIBRARY"
FACTORY_NAME = "frontseat_driver_load"

DRIVER_POINT = ExtensionPoint(group="goby_frontseat.drivers", what="frontseat driver library", source=ENV_VAR,
                              library_prefix="goby_frontseat_",
                              builtin=MappingProxyType({"basic_simulator": "frontseat.basic_simulator_driver"}))
HELM_INTERFACE_POINT = ExtensionPoint(group="goby_frontseat.helm_interfaces", what="helm interface",
                                      source="[goby.moos.protobuf.moos_helm]", entry_points_only=True,
                                      builtin=MappingProxyType(
                                          {"moos_helm": "translators.frontseat.translation:FrontSeatTranslation"}))
MOOS_HELM = "moos_helm"

DriverFactory = Callable[[config_pb.Config], FrontSeatDriver]


def load_driver_library(spec: str) -> ModuleType:
    """Import the driver module ``spec`` names; ExtensionError naming ``spec`` and the cause."""
    return load_module(DRIVER_POINT, spec)


def driver_factory(module: ModuleType, spec: str | None = None) -> DriverFactory:
    """The module's ``frontseat_driver_load``, checked to return a driver; ExtensionError if it has none."""
    spec = spec or module.__name__
    factory = module_function(DRIVER_POINT, spec, module, FACTORY_NAME)
    assert factory is not None

    def checked(cfg: config_pb.Config) -> FrontSeatDriver:
        driver = factory(cfg)
        if not isinstance(driver, FrontSeatDriver):
            raise DRIVER_POINT.error(spec, f"{FACTORY_NAME} returned {driver!r}, not a FrontSeatDriver")
        return driver

    return checked


def helm_interface_class(name: str = MOOS_HELM) -> type[SimpleThread]:
    """The thread class that connects a helm for the interface (``moos_helm``: pHelmIvP through a MOOSDB)."""
    loaded = load_extension(HELM_INTERFACE_POINT, name)
    if not (isinstance(loaded, type) and issubclass(loaded, SimpleThread)):
        raise HELM_INTERFACE_POINT.error(name, f"the entry point names {loaded!r}, not a SimpleThread subclass")
    return loaded
