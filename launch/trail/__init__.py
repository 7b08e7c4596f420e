"""The Goby3 course's trail mission (day 3): topside, USV and N AUVs, each launched by its own goby-launch."""
