"""The terminal views of a run: the live view of one drone (mission, behaviors, beliefs, events, keys) and the
one-line-per-drone view of a fleet."""
