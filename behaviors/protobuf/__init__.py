"""Config protos of the behaviours package (generated code is committed; see tools.generate_protos)."""
