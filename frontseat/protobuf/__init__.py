"""Frontseat protobuf messages (Goby3's packages, names and field numbers); generated code is committed.

Driver-specific config extensions live in their own files and are imported only by their driver, because
Goby3's drivers reuse extension numbers (basic simulator and Waveglider both extend Config with 1001).
"""
