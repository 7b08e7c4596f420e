"""Console-scriptless package marker for bench: run with python -m bench."""
