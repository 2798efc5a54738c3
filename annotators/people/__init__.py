"""Experts about people: what a person does (activity) and what it points at (pointing)."""
