"""The basic frontseat simulator (goby_basic_frontseat_simulator): a line protocol over TCP and a simple vehicle.

``protocol`` is the wire codec (shared with the driver), ``model`` the pure simulation, ``server`` the TCP
server and the ``frontseat-sim`` console script.
"""
