"""Frontseat interface: driver base class and state machine, the interface process, the basic simulator and its driver."""
