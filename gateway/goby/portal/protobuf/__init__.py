"""Protos owned by the portal (``goby-broker``'s ``GobyDaemonConfig``)."""
