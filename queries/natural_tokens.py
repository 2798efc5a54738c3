"""The tokenizer for natural phrases: words, numbers and quoted text with positions.

* a word starts with an ASCII letter and goes on with letters, digits,
  ``_``, ``-`` and ``'``; it is lower-cased, ``-`` becomes ``_`` and a
  possessive ``'s`` or other apostrophes are dropped; ``where's``,
  ``what's``, ``there's``, ``that's`` and ``that're`` become two words
  (``where is``) with one span;
* a number is digits with an optional fraction and unit (``12``, ``0.5m``);
* quoted text is ``"..."`` or ``“...”``; there are no escapes;
* ``? . ! , ; : #`` are skipped; any other character is an error.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from types import MappingProxyType
from typing import Literal

from queries.errors import QueryError, located_error
from queries.model import Span

TokenKind = Literal["word", "number", "string"]
"""What a token is."""

_SKIPPED = frozenset("?.!,;:#")
_QUOTES: MappingProxyType[str, str] = MappingProxyType({'"': '"', "\u201c": "\u201d"})
_CONTRACTIONS: MappingProxyType[str, tuple[str, ...]] = MappingProxyType(
    {
        "where's": ("where", "is"),
        "what's": ("what", "is"),
        "there's": ("there", "is"),
        "that's": ("that", "is"),
        "that're": ("that", "are"),
    }
)


@dataclass(frozen=True, slots=True)
class PhraseToken:
    """One token of a phrase: its kind, normalised text and source span."""

    kind: TokenKind
    text: str
    span: Span


def _is_ascii_letter(char: str) -> bool:
    """Return whether ``char`` is an ASCII letter."""
    return ("a" <= char <= "z") or ("A" <= char <= "Z")


def _is_word_char(char: str) -> bool:
    """Return whether ``char`` may continue a word."""
    return _is_ascii_letter(char) or ("0" <= char <= "9") or char in "_-'"


def _normalise_word(raw: str) -> str:
    """Lower-case a word, map ``-`` to ``_`` and drop apostrophes."""
    word = raw.lower().rstrip("-'")
    if word.endswith("'s"):
        word = word[:-2]
    return word.replace("'", "").replace("-", "_")


def _scan_number(text: str, start: int) -> int:
    """Return the end of the number starting at ``start``."""
    end = start
    while end < len(text) and "0" <= text[end] <= "9":
        end += 1
    if end + 1 < len(text) and text[end] == "." and "0" <= text[end + 1] <= "9":
        end += 1
        while end < len(text) and "0" <= text[end] <= "9":
            end += 1
    while end < len(text) and _is_ascii_letter(text[end]):
        end += 1
    return end


class _Positions:
    """Maps character offsets of one text to 1-based line and column."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.line_starts = [0]
        newline = text.find("\n")
        while newline >= 0:
            self.line_starts.append(newline + 1)
            newline = text.find("\n", newline + 1)

    def position(self, offset: int) -> tuple[int, int]:
        """Return the line and column of ``offset``."""
        line = bisect.bisect_right(self.line_starts, offset)
        return line, offset - self.line_starts[line - 1] + 1

    def span(self, start: int, end: int) -> Span:
        """Return the span of ``text[start:end]``."""
        return Span(*self.position(start), *self.position(end))

    def error(self, offset: int, message: str) -> QueryError:
        """Build an error located at ``offset``."""
        line, column = self.position(offset)
        return located_error(self.text, message, line, column)


def tokenize_phrase(text: str) -> list[PhraseToken]:
    """Split a phrase into tokens; raise :class:`QueryError` on a stray character."""
    positions = _Positions(text)
    tokens: list[PhraseToken] = []
    index = 0
    length = len(text)
    while index < length:
        char = text[index]
        if char.isspace() or char in _SKIPPED:
            index += 1
        elif _is_ascii_letter(char):
            end = index + 1
            while end < length and _is_word_char(text[end]):
                end += 1
            span = positions.span(index, end)
            raw = text[index:end].lower()
            words = _CONTRACTIONS.get(raw) or (_normalise_word(raw),)
            tokens.extend(PhraseToken("word", word, span) for word in words)
            index = end
        elif "0" <= char <= "9":
            end = _scan_number(text, index)
            tokens.append(PhraseToken("number", text[index:end], positions.span(index, end)))
            index = end
        elif char in _QUOTES:
            close = text.find(_QUOTES[char], index + 1)
            if close < 0:
                raise positions.error(index, "expected a closing quote for the text")
            content = text[index + 1 : close]
            tokens.append(PhraseToken("string", content, positions.span(index, close + 1)))
            index = close + 1
        else:
            raise positions.error(index, f"expected a word, not {char!r}")
    return tokens
