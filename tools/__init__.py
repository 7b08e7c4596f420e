"""Developer tools that are not installed with the packages (protobuf code generation)."""
