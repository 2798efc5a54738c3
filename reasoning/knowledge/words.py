"""Word normalisation for looking up ontology terms by label, synonym, name or plural."""

from __future__ import annotations

import re
import unicodedata

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
