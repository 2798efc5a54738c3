"""Matching words asked for against text an OCR expert read: containment, case ignored, OCR errors tolerated.

``text_matches("lactose free", "MILK lactose free")`` holds: every asked word must be found among the read words
within an edit distance of ``len(word) // OCR_LETTERS_PER_ERROR``, anywhere in the read text with its spaces
removed (OCR splits and joins words); a word shorter than that must be read exactly, as a word of its own.
"""

from __future__ import annotations

import re

OCR_LETTERS_PER_ERROR = 4
"""One wrong, missing or extra character is tolerated per this many letters of an asked word."""

_WORD = re.compile(r"[0-9a-z]+")


def words(text: str) -> list[str]:
    """The lower-case runs of letters and digits in ``text``."""
    return _WORD.findall(text.lower())


def substring_distance(word: str, text: str) -> int:
    """The least edit distance between ``word`` and any substring of ``text`` (Sellers' algorithm)."""
    previous = [0] * (len(text) + 1)
    for i, letter in enumerate(word, start=1):
        current = [i] + [0] * len(text)
        for j, other in enumerate(text, start=1):
            current[j] = min(previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (letter != other))
        previous = current
    return min(previous)


def word_found(word: str, read: list[str]) -> bool:
    """True when ``word`` occurs in the read words, within its tolerated number of OCR errors."""
    allowed = len(word) // OCR_LETTERS_PER_ERROR
    joined = "".join(read)
    if allowed == 0:
        return word in read
    return substring_distance(word, joined) <= allowed


def text_matches(wanted: str, read: str) -> bool:
    """True when every word of ``wanted`` is found in ``read`` (see the module docstring); an empty ``wanted``
    matches anything."""
    found = words(read)
    return all(word_found(word, found) for word in words(wanted))
