"""The texts a belief store interns: attribute names, attribute values and expert sets, each stored once in the
append-only table ``interned`` (code, text) and referred to by its integer code in the packed attribute supports.

A code, once committed, never changes and is never reused, so a connection may keep what it has read: it reads the
table again only when it meets a code it does not know (another connection interned it). Codes the connection
interned itself are kept only if their transaction commits (:meth:`InternedTexts.forget` after a rollback).
"""

from __future__ import annotations

import json
import sqlite3
import struct
from collections.abc import Callable, Iterator, Set

INTERN = "INSERT OR IGNORE INTO interned (text) VALUES (?)"
"""The statement that interns a text (its code: the next rowid)."""


class InternedTexts:
    """One connection's view of the ``interned`` table (codes by text, texts by code, expert sets)."""

    def __init__(self) -> None:
        self.codes: dict[str, int] = {}
        """Code of each known text (read directly on the hot path; :meth:`code` when missing)."""
        self.expert_codes: dict[frozenset[str], int] = {}
        """Code of each known expert set (its text: the JSON list of its sorted names)."""
        self.texts: dict[int, str] = {}
        """Text of each known code (read directly on the hot path; :meth:`text` when missing)."""
        self.expert_sets: dict[int, tuple[str, ...]] = {}
        """Expert names of each known expert-set code (:meth:`experts` when missing)."""

    def code(self, conn: sqlite3.Connection, text: str, write: Callable[[str, list[tuple]], None]) -> int:
        """The code of ``text``, interned with ``write(statement, rows)`` when new (inside a write transaction)."""
        found = self.codes.get(text)
        if found is None:
            write(INTERN, [(text,)])
            found = int(conn.execute("SELECT code FROM interned WHERE text = ?", (text,)).fetchone()[0])
            self.codes[text] = found
            self.texts[found] = text
        return found

    def experts_code(
        self, conn: sqlite3.Connection, experts: Set[str], write: Callable[[str, list[tuple]], None]
    ) -> int:
        """The code of an expert set (see :meth:`code`)."""
        key = frozenset(experts)
        found = self.expert_codes.get(key)
        if found is None:
            found = self.expert_codes[key] = self.code(conn, json.dumps(sorted(key)), write)
        return found

    def text(self, conn: sqlite3.Connection, code: int) -> str:
        """The text of ``code`` (the table read again when unknown; KeyError when it is not there either)."""
        found = self.texts.get(code)
        if found is None:
            self._load(conn)
            found = self.texts[code]
        return found

    def experts(self, conn: sqlite3.Connection, code: int) -> tuple[str, ...]:
        """The expert names of an expert-set code."""
        found = self.expert_sets.get(code)
        if found is None:
            found = self.expert_sets[code] = tuple(json.loads(self.text(conn, code)))
        return found

    def forget(self) -> None:
        """Drop everything known (after a rollback, which may have undone codes interned here)."""
        self.codes.clear()
        self.expert_codes.clear()
        self.texts.clear()
        self.expert_sets.clear()

    def _load(self, conn: sqlite3.Connection) -> None:
        for code, text in conn.execute("SELECT code, text FROM interned"):
            self.codes[text] = code
            self.texts[code] = text


DecodedSupport = tuple[int, int, float, int, int, float, float, str, str, tuple[str, ...]]
"""A packed support's fields (name code, value code, log-odds, count, expert-set code, first seen, last seen) followed
by its attribute name, value and expert names as texts."""


def decoded_supports(
    packed: bytes, record: struct.Struct, interned: InternedTexts, conn: sqlite3.Connection
) -> Iterator[DecodedSupport]:
    """Each support of a packed attribute column (``record``: one support's layout) with its codes read as texts."""
    texts, expert_sets = interned.texts, interned.expert_sets
    for name_code, value_code, log_odds, count, experts, first_seen, last_seen in record.iter_unpack(packed):
        name = texts.get(name_code)
        if name is None:
            name = interned.text(conn, name_code)
        value = texts.get(value_code)
        if value is None:
            value = interned.text(conn, value_code)
        names = expert_sets.get(experts)
        if names is None:
            names = interned.experts(conn, experts)
        yield name_code, value_code, log_odds, count, experts, first_seen, last_seen, name, value, names
