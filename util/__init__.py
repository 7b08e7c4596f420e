"""Shared ground for every top-level package: logging set-up, geodesy, process lifecycle, extension loading.

It imports nothing else of this project, so any package may use it (see docs/ARCHITECTURE.md, layering).
"""
