"""Groups of the USV command path (names as in the Goby3 course's ``groups.h`` where the course has them)."""

from __future__ import annotations

from gateway.goby.portal.group import Group

# On the vehicle: usv-manager republishes here; CommandTranslation subscribes (the course's usv_command, 0).
usv_command = Group("goby3_course::usv_command", 0)

# Shore -> vehicle: the stand-in for the course's intervehicle usv_command link (shore and vehicle share a broker,
# so the two legs need different groups, or the translator would see every command twice).
shore_usv_command = Group("goby3_course::shore::usv_command", 0)

# Acknowledgements (USVCommandAck) from usv-manager and CommandTranslation to usv-command.
usv_command_ack = Group("goby3_course::usv_command_ack")
