"""Classifications of ontology states proven coherent, kept beside the user file so edits need not rerun HermiT.

A state is the exact content of every source: the shipped (and extra) Turtle files, the annotator classes' triples and
the user file; :func:`state_key` digests it. A :class:`Classification` records, for one state HermiT found consistent
with no unsatisfiable class, each ``rk:`` class's inferred direct parents and ancestors. The editor stores the
classification of every state it proves coherent (by a full HermiT run, or by the incremental check of new classes on
top of a stored one: :mod:`reasoning.knowledge.fresh_classes`) in ``<file>.reasoner.json``, the last few states only.
The file is a cache: deleting it only costs one HermiT run.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

from reasoning.knowledge.atomic_write import write_atomically
from reasoning.knowledge.index import Inferred

_KEPT = 8


def cache_path(user_file: Path) -> Path:
    """The classification cache of a user file: ``<file>.reasoner.json`` beside it."""
    return user_file.with_name(user_file.name + ".reasoner.json")


def sources_digest(files: Iterable[Path], annotator_digest: str) -> str:
    """A digest of the read-only sources: each file's name and bytes, and the annotator triples' digest."""
    digest = hashlib.sha256(annotator_digest.encode("ascii"))
    for path in files:
        digest.update(path.name.encode("utf-8") + b"\0" + hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()


def state_key(sources: str, user_file_bytes: bytes) -> str:
    """The key of the state made of the read-only sources (their digest) and the user file's content."""
    return hashlib.sha256(sources.encode("ascii") + hashlib.sha256(user_file_bytes).digest()).hexdigest()


@dataclass(frozen=True)
class Classification:
    """The inferred class hierarchy of a coherent state; ``how`` says how coherence was proven."""

    key: str
    parents: Mapping[str, frozenset[str]]
    ancestors: Mapping[str, frozenset[str]]
    how: str

    @property
    def inferred(self) -> Inferred:
        """As the index takes it."""
        return Inferred(self.parents, self.ancestors)

    def without(self, key: str, names: Iterable[str], how: str) -> Classification:
        """The classification after classes nothing else mentions were removed."""
        gone = set(names)
        return Classification(
            key,
            {n: p - gone for n, p in self.parents.items() if n not in gone},
            {n: a - gone for n, a in self.ancestors.items() if n not in gone},
            how,
        )

    def extended(
        self, key: str, parents: Mapping[str, frozenset[str]], ancestors: Mapping[str, frozenset[str]], how: str
    ) -> Classification:
        """The classification with new classes added (existing classes keep their place)."""
        return Classification(key, {**self.parents, **parents}, {**self.ancestors, **ancestors}, how)


class ReasonerCache:
    """The stored classifications of one user file's recent coherent states."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)

    def get(self, key: str) -> Classification | None:
        """The classification of state ``key``, or None."""
        for record in self._records():
            if record.get("key") == key:
                with contextlib.suppress(KeyError, TypeError, AttributeError):
                    return Classification(
                        key,
                        {n: frozenset(p) for n, p in record["parents"].items()},
                        {n: frozenset(a) for n, a in record["ancestors"].items()},
                        record["how"],
                    )
        return None

    def put(self, classification: Classification) -> None:
        """Store a classification (the newest first; older states beyond the last few are dropped)."""
        record = {
            "key": classification.key,
            "how": classification.how,
            "parents": {n: sorted(p) for n, p in sorted(classification.parents.items())},
            "ancestors": {n: sorted(a) for n, a in sorted(classification.ancestors.items())},
        }
        records = [record, *(r for r in self._records() if r.get("key") != classification.key)][:_KEPT]
        write_atomically(self.path, json.dumps(records, separators=(",", ":")).encode("utf-8"))

    def _records(self) -> list[dict]:
        try:
            records = json.loads(self.path.read_text(encoding="utf-8"))
        except (FileNotFoundError, ValueError):
            return []
        return [r for r in records if isinstance(r, dict)] if isinstance(records, list) else []
