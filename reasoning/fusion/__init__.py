"""Fusion of expert statements: per-attribute fusion rule, per-frame objects, association with beliefs and
tracking across frames."""
