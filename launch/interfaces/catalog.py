"""The applications we ship, and the modules whose code makes up each one's interface.

Only the listed modules are analysed (as goby_clang_tool sees only a target's own sources): a plugin that
imports another plugin's module does not inherit its calls. A gateway plugin is listed as its own entry whose interface is merged into ``moos-gateway`` in a deployment
(the ``application:`` override of a deployment entry), as Goby lists its plugin libraries.
"""

from __future__ import annotations

from launch.interfaces.analyze import analyze_modules
from launch.interfaces.interface_yaml import dumps

SHIPPED_APPLICATIONS: dict[str, list[str]] = {
    "frontseat-interface": ["frontseat.interface"],
    "usv-manager": ["translators.apps.usv_manager"],
    "usv-command": ["translators.apps.usv_command"],
    "auv-manager": ["translators.apps.auv_manager", "translators.trail.auv_manager"],
    "topside-manager": ["translators.apps.topside_manager", "translators.trail.topside_manager"],
    "usv-health-monitor": ["translators.apps.usv_health_monitor"],
    "goby-coroner": ["gateway.apps.goby_coroner"],
    "goby-opencpn-interface": ["frontseat.apps.goby_opencpn_interface"],
    "moos-gateway-frontseat-plugin": ["translators.frontseat.translation"],
    "moos-gateway-usv-command-plugin": ["translators.usv.command_translation"],
    "moos-gateway-node-report-plugin": ["translators.node_report"],
    "goby-helm-example": ["behaviors.apps.goby_helm_example"],
    "usv-mission-shore": ["launch.usv.shore"],
    "trail-mission-operator": ["launch.trail.operator"],
    "moos-gateway-goby3-course-plugin": ["translators.trail.ivp_helm_translation", "translators.usv.command_translation"],
}


def interface_file_name(application: str) -> str:
    """Goby's naming: ``<target>_interface.yml``."""
    return f"{application}_interface.yml"


def generate_text(application: str) -> str:
    """The interface YAML of a shipped application or of a dotted module name."""
    modules = SHIPPED_APPLICATIONS.get(application, [application])
    return dumps(analyze_modules(application, modules))
