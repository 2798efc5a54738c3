"""The edit history of a user ontology file: one JSON line per edit in ``<file>.history.jsonl`` beside it.

Each entry records its number, the time (UTC), the user, the action, the class (or other subject) and the triples
the edit added and removed (N-Triples lines, blank nodes labelled per entry: :mod:`reasoning.knowledge.folded_triples`),
and how it was checked; an undo also lists the edits it reverted. The editor appends an entry, fsynced, right after it
replaced the user file (holding the file's lock). A line that cannot be read (an editor killed mid-write) is skipped.
"""

from __future__ import annotations

import contextlib
import getpass
import json
import os
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from reasoning.knowledge.folded_triples import FoldedTriple, from_ntriples, to_ntriples

UNDO = "undo"
"""The action of an entry that reverts other entries."""


def history_path(user_file: Path) -> Path:
    """The history file of a user file: ``<file>.history.jsonl`` beside it."""
    return user_file.with_name(user_file.name + ".history.jsonl")


@dataclass(frozen=True)
class HistoryEntry:
    """One edit of the user file."""

    number: int
    time: str
    user: str
    action: str
    name: str
    added: tuple[str, ...]
    removed: tuple[str, ...]
    checked_by: str
    undoes: tuple[int, ...] = field(default=())

    @property
    def added_triples(self) -> frozenset[FoldedTriple]:
        """The triples the edit added."""
        return from_ntriples(self.added)

    @property
    def removed_triples(self) -> frozenset[FoldedTriple]:
        """The triples the edit removed."""
        return from_ntriples(self.removed)

    @property
    def summary(self) -> str:
        """``add-object OatMilk`` / ``undo of 3, 2``."""
        if self.action == UNDO:
            return f"undo of {', '.join(map(str, self.undoes))}"
        return f"{self.action} {self.name}".strip()


def now() -> str:
    """The current UTC time, to the second, ISO 8601."""
    return datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


def current_user() -> str:
    """The login name of whoever runs the edit ("unknown" when there is none)."""
    try:
        return getpass.getuser()
    except (OSError, KeyError):
        return "unknown"


class EditHistory:
    """Reads and appends the history file of one user ontology file."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)

    def entries(self) -> list[HistoryEntry]:
        """Every readable entry, oldest first."""
        try:
            lines = self.path.read_text(encoding="utf-8").splitlines()
        except FileNotFoundError:
            return []
        found = []
        for line in lines:
            with contextlib.suppress(ValueError, TypeError, KeyError):
                record = json.loads(line)
                record["added"] = tuple(record["added"])
                record["removed"] = tuple(record["removed"])
                record["undoes"] = tuple(record.get("undoes", ()))
                found.append(HistoryEntry(**record))
        return found

    def next_number(self) -> int:
        """The number the next entry gets."""
        return max((e.number for e in self.entries()), default=0) + 1

    def append(
        self,
        number: int,
        action: str,
        name: str,
        added: frozenset[FoldedTriple],
        removed: frozenset[FoldedTriple],
        checked_by: str,
        undoes: Sequence[int] = (),
    ) -> HistoryEntry:
        """Write one entry (a single fsynced line) and return it."""
        entry = HistoryEntry(
            number,
            now(),
            current_user(),
            action,
            name,
            tuple(to_ntriples(added)),
            tuple(to_ntriples(removed)),
            checked_by,
            tuple(undoes),
        )
        line = json.dumps(asdict(entry), ensure_ascii=False) + "\n"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open(self.path, "a", encoding="utf-8") as stream:
            stream.write(line)
            stream.flush()
            os.fsync(stream.fileno())
        return entry

    def undoable(self, count: int) -> list[HistoryEntry]:
        """The last ``count`` edits that are not undos and were not undone, newest first (fewer if there are not
        that many)."""
        entries = self.entries()
        undone = {n for e in entries if e.action == UNDO for n in e.undoes}
        candidates = [e for e in reversed(entries) if e.action != UNDO and e.number not in undone]
        return candidates[:count]
