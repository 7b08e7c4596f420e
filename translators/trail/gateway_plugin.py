"""The course's moos-gateway plugin (``libgoby3_course_moos_gateway_plugin.so``; entry point ``goby3_course``).

As the course's ``goby3_moos_gateway_load``: launches IvPHelmTranslation (contacts and AUV commands) and
CommandTranslation (USV commands); unload joins both.
"""

from __future__ import annotations

from translators.base import translator_plugin
from translators.trail.ivp_helm_translation import IvPHelmTranslation
from translators.usv.command_translation import CommandTranslation

load, unload = translator_plugin(IvPHelmTranslation, CommandTranslation)
