"""Shared resources: expensive objects (loaded models, OCR engines) that the annotators of many trees share.

A long-running instance builds a new tree for every task; without sharing, every tree would load its models
again. Each Annotator has a :class:`SharedResources`; by default its own (so a model is loaded once per
annotator instance), and a tree builder can hand every node one pool that lives as long as the service
(``trees.synthesis.build_tree(..., resources=pool)``). A resource is built once per key, under a lock, and
whoever uses it concurrently from several trees must lock it itself (see :class:`Guarded`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from typing import Generic, TypeVar

T = TypeVar("T")


@dataclass(frozen=True)
class Guarded(Generic[T]):
    """A resource with the lock its users take around each use (for objects that are not thread-safe)."""

    value: T
    lock: threading.Lock = field(default_factory=threading.Lock, compare=False)


class SharedResources:
    """Resources by key, each built on first request (see the module)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._items: dict[Hashable, object] = {}

    def get(self, key: Hashable, build: Callable[[], T]) -> T:
        """The resource under ``key``, built with ``build()`` on the first request (a failing build raises and
        stores nothing, so a later request tries again)."""
        with self._lock:
            if key not in self._items:
                self._items[key] = build()
            return self._items[key]  # type: ignore[return-value]

    def __len__(self) -> int:
        with self._lock:
            return len(self._items)
