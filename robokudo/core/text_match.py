"""Matching words asked for, or printed on a class of objects, against text an OCR expert read: containment, case
ignored, OCR errors tolerated (one rule for the query's text and the classifier's printed texts and brands).

``text_matches("lactose free", "MILK lactose free")`` holds: every asked word must be found among the read words
within an edit distance of ``len(word) // OCR_LETTERS_PER_ERROR`` ("CHEEL" is read "CHEEZ"), anywhere in the read
text with its spaces removed (OCR splits and joins words); a word shorter than ``MIN_JOINED_LETTERS`` must be read
exactly, as a word of its own ("tea" is not found in "steak").
"""

from __future__ import annotations

import re

OCR_LETTERS_PER_ERROR = 5
"""One wrong, missing or extra character is tolerated per this many letters of an asked word."""

MIN_JOINED_LETTERS = 4
"""An asked word of at least this many letters is also found inside a longer read word (OCR joined words)."""

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
    if len(word) < MIN_JOINED_LETTERS:
        return word in read
    return substring_distance(word, "".join(read)) <= len(word) // OCR_LETTERS_PER_ERROR


def text_matches(wanted: str, read: str) -> bool:
    """True when every word of ``wanted`` is found in ``read`` (see the module docstring); an empty ``wanted``
    matches anything."""
    found = words(read)
    return all(word_found(word, found) for word in words(wanted))


def phrase_found(phrase: str, read: str) -> bool:
    """True when a phrase printed on an object (a brand, "lactose free") is found in ``read``: its letters and
    digits with the spaces and punctuation removed, taken as one word (:func:`word_found`: "Cheez-It" in "CHEEZIT",
    "CHEEL IT" or "cheez it"; a phrase shorter than ``MIN_JOINED_LETTERS`` must be a read word of its own). False for
    a phrase without letters or digits."""
    joined = "".join(words(phrase))
    return bool(joined) and word_found(joined, words(read))
