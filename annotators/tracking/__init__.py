"""Trackers of a continuous task's target: a particle filter per target, for people and for objects."""
