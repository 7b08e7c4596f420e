"""Frontseat interface: driver base class and state machine, the interface process, the basic simulator and its driver.

See docs/frontseat.md. Entry points: ``frontseat.driver.FrontSeatDriver`` (write a driver),
``frontseat.groups`` (the portal groups), ``frontseat-interface`` / ``frontseat-sim`` (the processes),
``frontseat.testing`` (helpers for tests).
"""
