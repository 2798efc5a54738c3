"""The shipped ontology (Turtle files); this package only locates them."""

from pathlib import Path

NAMESPACE = "http://robokudo.org/ontology#"
"""The namespace of every term the project defines (``rk:``)."""

VOCABULARY_FILES: tuple[str, ...] = ("perception.ttl", "regions.ttl", "objects.ttl", "annotators.ttl")
"""The shipped files every knowledge base loads, in load order."""

DEFAULT_MAP_FILE = "kitchen_map.ttl"
"""The semantic map of the built-in kitchen scene, loaded unless another map is given."""

EXAMPLE_USER_MAP_FILE = "example_user_map.ttl"
"""An example of a user's own kitchen map (not loaded by default)."""

REGION_BOX_PROPERTIES: tuple[str, ...] = (
    "positionX",
    "positionY",
    "positionZ",
    "orientationX",
    "orientationY",
    "orientationZ",
    "orientationW",
    "sizeX",
    "sizeY",
    "sizeZ",
)
"""The ``rk:`` data properties that place a region box (regions.ttl): centre position, unit quaternion x-y-z-w
and size, in this order."""


def ontology_dir() -> Path:
    """The folder holding the shipped ``*.ttl`` files."""
    return Path(__file__).resolve().parent


def shipped_files(map_file: Path | None = None) -> tuple[Path, ...]:
    """The shipped vocabulary files plus a semantic map (default: the built-in kitchen's)."""
    folder = ontology_dir()
    semantic_map = map_file if map_file is not None else folder / DEFAULT_MAP_FILE
    return (*(folder / name for name in VOCABULARY_FILES), semantic_map)
