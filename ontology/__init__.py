"""The shipped ontology (Turtle files); this package only locates them."""

from pathlib import Path


def ontology_dir() -> Path:
    """The folder holding the shipped ``*.ttl`` files."""
    return Path(__file__).resolve().parent
