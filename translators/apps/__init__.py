"""Applications of the translators tree (console scripts), kept apart from the libraries they wire together."""
