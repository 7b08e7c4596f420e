"""Applications of the behaviors tree (console scripts): the MOOS helm and the Goby-side helm."""
