"""Protobuf support shared by every package: the code generator and third-party-shaped include files."""
