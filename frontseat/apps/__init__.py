"""Applications of the frontseat tree (console scripts): the interface process and the basic simulator."""
