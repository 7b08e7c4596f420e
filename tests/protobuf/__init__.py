"""Test-only protobuf messages, with their generated code committed (no protoc at test time)."""
