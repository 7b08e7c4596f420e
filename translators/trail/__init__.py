"""The trail mission of the Goby3 course (day 3): its DCCL messages and the library the trail apps share."""
