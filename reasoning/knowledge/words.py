"""Word normalisation for looking up ontology terms by label, synonym, name or plural."""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable

MAX_NAME_LENGTH = 64
"""Longest class name accepted by ontology edits, in characters."""

MAX_LABEL_LENGTH = 100
"""Longest label, synonym, printed text or brand accepted by ontology edits, in characters."""

_BREAKING_CATEGORIES = frozenset({"Cc", "Zl", "Zp"})
_CAMEL_BOUNDARY = re.compile(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])")


def word_key(text: str) -> str:
    """The lookup key of a word: case-folded, letters and digits only ("Cereal_Box" -> "cerealbox").

    Letters and digits of any script count ("コップ" keeps its characters); compatibility forms are unified first
    (full-width "ＣＵＰ" is "cup").
    """
    text = text.strip()
    if text.startswith("rk:"):
        text = text[3:]
    return "".join(ch for ch in unicodedata.normalize("NFKC", text).casefold() if ch.isalnum())


def control_characters(text: str) -> list[str]:
    """The control characters and line or paragraph separators in ``text`` (as escapes, e.g. ``\\n``), in order."""
    return [repr(ch)[1:-1] for ch in text if unicodedata.category(ch) in _BREAKING_CATEGORIES]


def one_line(text: str) -> str:
    """``text`` with every run of whitespace and control characters made one space, trimmed."""
    cleaned = "".join(" " if unicodedata.category(ch) in _BREAKING_CATEGORIES else ch for ch in text)
    return " ".join(cleaned.split())


def singular_keys(key: str) -> tuple[str, ...]:
    """Candidate singular forms of a (possibly plural) key, most likely first."""
    candidates: list[str] = []
    if key.endswith("ies") and len(key) > 3:
        candidates.append(key[:-3] + "y")
    if key.endswith("ves") and len(key) > 3:
        candidates += [key[:-3] + "f", key[:-3] + "fe"]
    if key.endswith("es") and len(key) > 2:
        candidates.append(key[:-2])
    if key.endswith("s") and not key.endswith("ss") and len(key) > 1:
        candidates.append(key[:-1])
    return tuple(candidates)


def camel_words(name: str) -> str:
    """The words of a CamelCase name in lower case ("LactoseFreeMilk" -> "lactose free milk")."""
    return " ".join(part.lower() for part in _CAMEL_BOUNDARY.split(name.replace("_", " ")) if part.strip())


def camel_case(text: str) -> str:
    """A CamelCase name made of the words of ``text`` ("oat milk" -> "OatMilk")."""
    return "".join(part[:1].upper() + part[1:] for part in re.split(r"[^0-9A-Za-z]+", text) if part)


LETTERS_PER_TYPO = 3
"""A suggestion for an unknown word may differ from it by one slip (a wrong, missing, extra or swapped letter) per
this many letters of the word, at least one: "mlik" is "milk", "botle" "bottle"; "chair" is no "dairy"."""


def typo_distance(typed: str, known: str) -> int:
    """The number of slips between two keys: wrong, missing or extra letters and swapped neighbours (optimal string
    alignment distance)."""
    rows = [list(range(len(known) + 1))]
    for i, letter in enumerate(typed, start=1):
        row = [i] + [0] * len(known)
        for j, other in enumerate(known, start=1):
            row[j] = min(rows[-1][j] + 1, row[j - 1] + 1, rows[-1][j - 1] + (letter != other))
            if i > 1 and j > 1 and letter == known[j - 2] and typed[i - 2] == other:
                row[j] = min(row[j], rows[-2][j - 2] + 1)
        rows.append(row)
    return rows[-1][-1]


def close_keys(typed: str, keys: Iterable[str], count: int = 3) -> list[str]:
    """Up to ``count`` of ``keys`` a person may have meant by ``typed`` (a key, :func:`word_key`): within its slips
    (:data:`LETTERS_PER_TYPO`), fewest slips first, then as listed."""
    allowed = max(1, len(typed) // LETTERS_PER_TYPO)
    scored = (
        (typo_distance(typed, key), index, key)
        for index, key in enumerate(keys)
        if abs(len(key) - len(typed)) <= allowed  # more slips than that in the length alone
    )
    return [key for slips, _, key in sorted(s for s in scored if s[0] <= allowed)][:count]
