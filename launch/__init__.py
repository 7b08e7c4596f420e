"""The launcher (goby_launch's file format) and the missions."""
