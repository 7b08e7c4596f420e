"""The Translator base class and the shipped translators (frontseat, USV command, node report)."""
