"""The errors of the reasoning layer."""

from __future__ import annotations

from collections.abc import Sequence


class OntologyError(Exception):
    """The ontology files are invalid; ``problems`` lists every problem found."""

    def __init__(self, problems: Sequence[str], heading: str = "invalid ontology") -> None:
        self.problems = tuple(problems)
        super().__init__(f"{heading}:\n  " + "\n  ".join(self.problems) if self.problems else heading)


class InconsistentOntologyError(OntologyError):
    """The reasoner found unsatisfiable classes or an inconsistent ontology."""


class TermError(KeyError):
    """Base of the word-lookup errors; ``str()`` gives the plain message."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message

    def __str__(self) -> str:
        return self.message


class UnknownTermError(TermError):
    """A word or name the ontology does not know; ``suggestions`` holds close matches; ``advice`` (said when there
    are none) what to ask or do instead."""

    def __init__(self, word: str, what: str = "term", suggestions: Sequence[str] = (), advice: str = "") -> None:
        self.word = word
        self.suggestions = tuple(suggestions)
        if self.suggestions:
            hint = f"; did you mean {', '.join(repr(s) for s in self.suggestions)}?"
        else:
            hint = f"; {advice}" if advice else ""
        super().__init__(f"unknown {what} {word!r}{hint}")


class AmbiguousTermError(TermError):
    """A word that names several terms of the same kind; ``candidates`` lists them."""

    def __init__(self, word: str, candidates: Sequence[str]) -> None:
        self.word = word
        self.candidates = tuple(candidates)
        super().__init__(f"{word!r} is ambiguous: it may mean {', '.join(self.candidates)}")


class EditRejectedError(ValueError):
    """An ontology edit failed validation; nothing was written. ``problems`` says why."""

    def __init__(self, problems: Sequence[str]) -> None:
        self.problems = tuple(problems)
        super().__init__("edit rejected, nothing was written:\n  " + "\n  ".join(self.problems))
