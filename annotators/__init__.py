"""Readers and vision experts, by role: readers/, cloud/, image/, text/, classification/, the shared geometry/
helpers, the simulation/ of the built-in kitchen, and the catalog that turns annotator names into classes."""
