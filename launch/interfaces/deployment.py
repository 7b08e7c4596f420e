"""Deployment YAML (``deployment:`` and ``platforms:``): which applications run on which platform and module."""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from launch.errors import LaunchError
from launch.interfaces.interface_yaml import InterfaceFileError, load
from launch.interfaces.model import ApplicationInterface

log = logging.getLogger(__name__)

NO_MODULE = "nomodule"
INTERFACES_DIR_TOKEN = "@GOBY_INTERFACES_DIR@"
DEFAULT_INTERFACES_DIR = Path(__file__).resolve().parents[2] / "docs" / "interfaces"


class DeploymentError(LaunchError, ValueError):
    """A deployment file that cannot be used; the message names the file and the problem."""


@dataclass
class Module:
    name: str
    applications: dict[str, ApplicationInterface] = field(default_factory=dict)


@dataclass
class Platform:
    name: str
    modules: dict[str, Module] = field(default_factory=dict)


@dataclass
class Deployment:
    name: str
    platforms: dict[str, Platform] = field(default_factory=dict)


def _interfaces_dir() -> str:
    return os.environ.get("GOBY_INTERFACES_DIR", str(DEFAULT_INTERFACES_DIR))


def _resolve(entry: str, base: Path) -> Path:
    path = Path(entry.replace(INTERFACES_DIR_TOKEN, _interfaces_dir()))
    return path if path.is_absolute() else base / path


def _merge(into: ApplicationInterface, other: ApplicationInterface) -> None:
    into.entries |= other.entries
    for name, info in other.threads.items():
        into.threads.setdefault(name, info)


def _load_interfaces(raw: object, base: Path, where: str, module: Module) -> None:
    if not isinstance(raw, list):
        raise DeploymentError(f"{where}: 'interfaces' must be a sequence")
    for item in raw:
        if isinstance(item, str):
            file, override = item, None
        elif isinstance(item, dict):
            if "file" not in item:
                raise DeploymentError(f"{where}: Must specify file: for each interfaces entry")
            file, override = str(item["file"]), item.get("application")
        else:
            raise DeploymentError(f"{where}: bad interfaces entry {item!r}")
        try:
            interface = load(_resolve(file, base))
        except InterfaceFileError as exc:
            log.error("Failed to parse %s: %s", file, exc)  # as Goby: report and carry on with the rest
            continue
        if override:
            interface.application = str(override)
        if interface.application in module.applications:
            _merge(module.applications[interface.application], interface)
        else:
            module.applications[interface.application] = interface


def load_deployment(path: str | Path) -> Deployment:
    """Read a deployment file and the interface files it names (relative to the deployment file)."""
    path = Path(path)
    try:
        # Substitute before parsing, as Goby's CMake configure step does: an unquoted `- @GOBY_INTERFACES_DIR@/x`
        # is not valid YAML (`@` cannot start a token), yet the course's deployment files are written that way.
        data = yaml.safe_load(path.read_text().replace(INTERFACES_DIR_TOKEN, _interfaces_dir()))
    except (OSError, yaml.YAMLError) as exc:
        raise DeploymentError(f"{path}: cannot read deployment: {exc}") from exc
    if not isinstance(data, dict) or "deployment" not in data:
        raise DeploymentError(f"{path}: Must specify deployment: <name> in deployment YAML file")
    platforms = data.get("platforms")
    if not isinstance(platforms, list):
        raise DeploymentError(f"{path}: Must specify platforms: as a sequence in deployment YAML file")
    deployment = Deployment(str(data["deployment"]))
    for raw_platform in platforms:
        if not isinstance(raw_platform, dict) or "name" not in raw_platform:
            raise DeploymentError(f"{path}: each platform needs a name")
        platform = Platform(str(raw_platform["name"]))
        where = f"{path} (platform {platform.name})"
        if "modules" in raw_platform:
            for raw_module in raw_platform["modules"] or []:
                module = Module(str(raw_module["name"]))
                if "interfaces" not in raw_module:
                    raise DeploymentError(f"{where}: module {module.name} needs an 'interfaces' sequence")
                _load_interfaces(raw_module["interfaces"], path.parent, where, module)
                platform.modules[module.name] = module
        else:
            module = Module(NO_MODULE)
            _load_interfaces(raw_platform.get("interfaces") or [], path.parent, where, module)
            platform.modules[NO_MODULE] = module
        deployment.platforms[platform.name] = platform
    return deployment
