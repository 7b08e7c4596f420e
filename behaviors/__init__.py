"""Behaviour files for pHelmIvP and a small pure-Python helm that runs them."""
