"""The knowledge base as the application loads it: the ontology files plus the annotators of a catalog."""

from __future__ import annotations

from typing import Any

from annotators.catalog import AnnotatorCatalog
from reasoning.knowledge.knowledge_base import KnowledgeBase


def load_knowledge_base(catalog: AnnotatorCatalog | None = None, **options: Any) -> KnowledgeBase:
    """``KnowledgeBase.load(**options)`` with the annotators of ``catalog`` (default: this project's)."""
    return KnowledgeBase.load(**options)
