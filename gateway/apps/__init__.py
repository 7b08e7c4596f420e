"""Console scripts of the gateway tree that are not part of one component (thin: argv, wiring)."""
