"""Config protos of the behaviours package (generated code is committed; see gateway.protobuf.generate)."""
