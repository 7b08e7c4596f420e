"""The Goby3 course's message library (``libgoby3_course_messages.so`` in the course's liaison config).

Importing this module registers the course's protobuf types, so ``load_shared_library:
"libgoby3_course_messages.so"`` (the entry point ``goby3_course_messages`` of ``goby_liaison.protobuf``) makes
them nameable in the commander, as the course's shared library does for Goby's liaison.
"""

from translators.usv.protobuf import command_ack_pb2, command_dccl_pb2

TYPES = (command_dccl_pb2.USVCommand, command_ack_pb2.USVCommandAck)
