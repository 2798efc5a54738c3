"""The application's knowledge base: the ontology files plus every annotator class of the catalog.

Annotators are declared by their Python classes; :func:`load_knowledge_base` is how every command loads the
knowledge base, so the planner knows exactly the experts the ``annotators`` package (and ``extra_annotators``)
defines.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

from annotators.catalog import AnnotatorCatalog
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.core.annotator import Annotator


def load_knowledge_base(
    user_file: Path | None = None,
    *,
    reason: bool = False,
    map_file: Path | None = None,
    extra_files: Sequence[Path] = (),
    files: Sequence[Path] | None = None,
    extra_annotators: Iterable[type[Annotator]] = (),
    catalog: AnnotatorCatalog | None = None,
) -> KnowledgeBase:
    """:meth:`KnowledgeBase.load` with the annotator classes of ``catalog`` (default: this package's catalog
    plus ``extra_annotators``)."""
    if catalog is None:
        catalog = AnnotatorCatalog.discover(extra=extra_annotators)
    return KnowledgeBase.load(
        user_file, reason=reason, map_file=map_file, extra_files=extra_files, files=files, annotators=catalog.values()
    )
