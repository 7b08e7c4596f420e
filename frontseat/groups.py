"""The frontseat interface's publish/subscribe groups, with Goby3's exact strings (``groups.h``).

Payloads interoperate with Goby3 only if the group strings match byte for byte, so they are spelled out
here once and everyone (interface, translators, helm, tests) imports them.
"""

from __future__ import annotations

from gateway.goby.portal import Group

_PREFIX = "goby::middleware::frontseat::"

node_status = Group(_PREFIX + "node_status")  # NodeStatus, interface -> everyone
desired_course = Group(_PREFIX + "desired_course")  # DesiredCourse, helm -> interface
raw_in = Group(_PREFIX + "raw_in")  # Raw, every line read from the frontseat
raw_out = Group(_PREFIX + "raw_out")  # Raw, every line written to the frontseat
raw_send_request = Group(_PREFIX + "raw_send_request")  # Raw, payload -> frontseat (LISTEN/COMMAND)
command_request = Group(_PREFIX + "command_request")  # CommandRequest, payload -> interface (COMMAND)
command_response = Group(_PREFIX + "command_response")  # CommandResponse, interface -> payload
data_from_frontseat = Group(_PREFIX + "data_from_frontseat")  # InterfaceData, interface -> everyone
data_to_frontseat = Group(_PREFIX + "data_to_frontseat")  # InterfaceData, payload -> frontseat
helm_state = Group(_PREFIX + "helm_state")  # HelmStateReport, helm -> interface
status = Group(_PREFIX + "status")  # InterfaceStatus, every status_period

# goby::middleware::groups::datum_update (navigation/groups.h): DatumUpdate moves the UTM origin.
datum_update = Group("goby::datum_update")

ALL = (
    node_status,
    desired_course,
    raw_in,
    raw_out,
    raw_send_request,
    command_request,
    command_response,
    data_from_frontseat,
    data_to_frontseat,
    helm_state,
    status,
)
