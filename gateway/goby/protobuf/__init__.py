"""Goby3 protos every application uses (AppConfig, InterProcessPortalConfig, ...) and third-party-shaped include files (DCCL options)."""
