"""The USV mission: settings, config generation, launch file, shore commands, demo."""
