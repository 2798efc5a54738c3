"""Natural phrasing: ``find the red cup on the table`` -> :class:`Query`.

A small tokenizer (:mod:`queries.natural_tokens`) feeds a rule-based phrase
parser; the word tables are data in :mod:`queries.lexicon`.  The mapping:

==============================================  =====================================
phrase                                          model
==============================================  =====================================
find / detect / locate / get / search (for) /   ``detect``
look for / where is / is there / show (me) /
list / (do you) see / what is + place
track / follow / keep track of                  ``track``
inspect / examine / look at / check             ``inspect``
what color / size / shape is X                  ``inspect { obj: { ..., color: ? } }``
how many X (are there) / count X                ``detect`` every X (no result limit)
scan X [for Y]                                  ``scan { region: X, for: Y }``
find / look for free space on X                 ``scan { region: X, for: free_space }``
where can I put / place / set X on Y            ``scan { free_space: { region: Y, for: X } }``
stop / cancel [task] N, stop all                ``stop { task: N }``, ``task: all``
noun words (unknown words joined by ``_``)      ``obj: { type: cereal_box }``
plural head noun                                singular ``type``, no result limit
a / an / the / this / my ... + singular noun    ``max_results: 1`` (detect, track)
all / two / 3 (of) the / my / these + noun      the quantity sets the limit, not ``the``
the / these two / 3 + noun                      the quantity sets the limit
the red one / the red ones                      ``one`` names no class: ``color: red``
the top / leftmost / closest / biggest X         ``select: top`` (one object: ``max_results: 1``)
(also bottom, rightmost, farthest, smallest,
highest, nearest, left, right...)
X on the left / at the top / from the right     ``select: leftmost`` / ``top`` / ``rightmost``
the second biggest X / second X from the left   ``select: { by: biggest, rank: 2 }``
find me / get me                                ``detect`` (``me`` is not the object)
me / him / her / us / them (alone)              ``type: person`` (``follow me``)
two ... ten, or a number, before the noun       ``max_results: N`` (detect, track)
colour adjective (red, dark red, grey...)       ``color: red`` (several: a list)
size adjective (small, little, big, tiny...)    ``size: small`` / ``large``
shape adjective (round, cylindrical, boxy...)   ``shape: sphere`` / ``cylinder`` / ``box``
shape noun (box, cube, cylinder, sphere)        ``shape: box`` and no ``type``
transparent / clear / opaque                    ``transparent: true`` / ``false`` (a property)
something / anything / everything + adjectives  no ``type``; ``something`` asks for one
anywhere / everywhere                           ``location: anywhere`` (no region restriction)
noun + number (``object 12``, ``cup no 3``)     ``id: 12``; object/item/thing set no type
in / inside / on / at / near / next to /        ``location: { in: fridge }`` etc.
under / behind / above / in front of X
"quoted text" (``with "..."``, ``labelled``)    ``text: "..."``
find "text" (the quoted text as the object)     ``obj: { text: "..." }``
that is / which is + adjectives                 the same keys as the adjectives
with X (not quoted)                             ``with: X``
==============================================  =====================================

Articles are dropped; place phrases are joined with ``_`` and their last
word singularised.  Words not in the tables are never an error: they stay as
they are for the reasoning layer.  A phrase without a known verb, with an
empty object or place, or with a token that cannot be placed raises a
located :class:`QueryError` at the first such token.
"""

from __future__ import annotations

import difflib
from collections.abc import Collection, Iterable
from dataclasses import dataclass, field

from queries.errors import QueryError, located_error
from queries.lexicon import (
    ADJECTIVE_KEYS,
    ANYWHERE_WORDS,
    COLOR_MODIFIERS,
    COLORS,
    CONJUNCTIONS,
    COUNT_QUESTIONS,
    COUNT_TAILS,
    COUNT_VERBS,
    COUNT_WORDS,
    FILLERS,
    GENERIC_NOUNS,
    ID_MARKERS,
    IGNORED_WORDS,
    INDEFINITE_PRONOUNS,
    INVARIANT_WORDS,
    IRREGULAR_PLURALS,
    LIMITING_DETERMINERS,
    OPEN_DETERMINERS,
    ORDINALS,
    PARTITIVE_OF,
    PERSON_NOUN,
    PERSONAL_PRONOUNS,
    PLACEMENT_VERBS,
    PLURAL_ONLY,
    PLURAL_SUFFIXES,
    PREPOSITIONS,
    QUESTION_ATTRIBUTES,
    QUESTION_VERBS,
    RELATIVE_CLAUSES,
    SCAN_FOR,
    SCAN_TARGETS,
    SELECTION_PHRASES,
    SELECTION_WORDS,
    SHAPE_NOUNS,
    STOP_ALL_WORDS,
    STOP_TASK_WORDS,
    TEXT_MARKERS,
    VERBS,
)
from queries.model import (
    ANYWHERE,
    FREE_SPACE_KEY,
    POINTING_KEY,
    Asked,
    Block,
    Field,
    ListValue,
    Number,
    Query,
    Span,
    String,
    Symbol,
    Value,
)
from queries.natural_tokens import PhraseToken, tokenize_phrase
from queries.selection import SELECT_KEY
from queries.units import UnitError, parse_quantity
from queries.validation import MAX_QUERY_LENGTH, check_length, validate_query

VERB_EXAMPLES: tuple[str, ...] = ("find", "track", "inspect", "scan", "stop")
"""The verbs named when a phrase starts with none."""

_LONGEST_PHRASE = max(
    len(words)
    for table in (VERBS, PLACEMENT_VERBS, PREPOSITIONS, FILLERS, TEXT_MARKERS, SELECTION_PHRASES)
    for words in table
)


def singularise(word: str) -> tuple[str, bool]:
    """Return ``(singular, was_plural)`` by the suffix rules: ``boxes`` -> ``box``."""
    if word in IRREGULAR_PLURALS:
        return IRREGULAR_PLURALS[word], True
    if word in PLURAL_ONLY:
        return word, True
    if word in INVARIANT_WORDS or len(word) < 3:
        return word, False
    for suffix, replacement in PLURAL_SUFFIXES:
        if not word.endswith(suffix):
            continue
        if suffix == replacement:
            return word, False
        if len(word) > len(suffix) + 1:
            return word[: len(word) - len(suffix)] + replacement, True
    return word, False


def _join_span(first: Span, last: Span) -> Span:
    """Return the span from the start of ``first`` to the end of ``last``."""
    return Span(first.line, first.column, last.end_line, last.end_column)


@dataclass
class _Attribute:
    """One key found in a phrase, with its values and where they were said."""

    key: str
    values: list[Value]
    span: Span

    def as_field(self) -> Field:
        value = self.values[0] if len(self.values) == 1 else ListValue(tuple(self.values))
        return Field(self.key, value, self.span)


@dataclass
class _ObjectPhrase:
    """What a phrase says about the object, collected while parsing."""

    start: Span
    end: Span
    noun: str = ""
    noun_span: Span | None = None
    generic: bool = False
    plural: bool = False
    limit: int | None = None
    limit_span: Span | None = None
    object_id: Field | None = None
    adjectives: dict[str, _Attribute] = field(default_factory=dict)
    extras: list[Field] = field(default_factory=list)
    locations: list[Field] = field(default_factory=list)
    location_span: Span | None = None
    anywhere: Span | None = None
    selection: str | None = None
    selection_span: Span | None = None
    rank: int = 1
    rank_span: Span | None = None

    def add_adjective(self, key: str, value: Value, span: Span) -> None:
        found = self.adjectives.get(key)
        if found is None:
            self.adjectives[key] = _Attribute(key, [value], span)
        else:
            found.values.append(value)

    def block(self) -> Block:
        fields: list[Field] = []
        if self.noun and (not self.generic or (self.object_id is None and self.is_bare())):
            fields.append(Field("type", Symbol(self.noun), self.noun_span or self.start))
        if self.object_id is not None:
            fields.append(self.object_id)
        for key, _ in ADJECTIVE_KEYS:
            if key in self.adjectives:
                fields.append(self.adjectives[key].as_field())
        fields.extend(self.extras)
        if self.locations:
            span = self.location_span or self.start
            fields.append(Field("location", Block(tuple(self.locations)), span))
        elif self.anywhere is not None:
            fields.append(Field("location", Symbol(ANYWHERE), self.anywhere))
        return Block(tuple(fields))

    def is_bare(self) -> bool:
        return not (self.adjectives or self.extras or self.locations or self.anywhere)

    def select(self, selection: str, span: Span) -> None:
        """Record the selection said at ``span``; a second one is an error (the caller locates it)."""
        if self.selection is not None and self.selection != selection:
            raise ValueError(f"expected one selection: '{self.selection}' is already asked")
        self.selection, self.selection_span = selection, self.selection_span or span

    def select_field(self) -> Field | None:
        """The ``select`` field (a block when a rank other than the first is asked), None without a selection."""
        if self.selection is None:
            return None
        span = self.selection_span or self.start
        if self.rank == 1:
            return Field(SELECT_KEY, Symbol(self.selection), span)
        rank_span = self.rank_span or span
        by = Field("by", Symbol(self.selection), span)
        return Field(
            SELECT_KEY, Block((by, Field("rank", Number(float(self.rank)), rank_span))), _join_span(rank_span, span)
        )


class _PhraseParser:
    """Parses one phrase; holds the tokens and the current position."""

    def __init__(self, text: str, tokens: Iterable[PhraseToken]) -> None:
        self.text = text
        self.tokens = [token for token in tokens if not (token.kind == "word" and token.text in IGNORED_WORDS)]
        self.index = 0

    # -- token access -----------------------------------------------------

    def current(self) -> PhraseToken | None:
        return self.tokens[self.index] if self.index < len(self.tokens) else None

    def word(self, ahead: int = 0) -> str | None:
        position = self.index + ahead
        if position < len(self.tokens) and self.tokens[position].kind == "word":
            return self.tokens[position].text
        return None

    def match(self, table: Collection[tuple[str, ...]]) -> tuple[str, ...] | None:
        """Return the longest entry of ``table`` starting here, without consuming it."""
        words: list[str] = []
        for ahead in range(_LONGEST_PHRASE):
            word = self.word(ahead)
            if word is None:
                break
            words.append(word)
        for size in range(len(words), 0, -1):
            candidate = tuple(words[:size])
            if candidate in table:
                return candidate
        return None

    def take(self, count: int = 1) -> list[PhraseToken]:
        taken = self.tokens[self.index : self.index + count]
        self.index += len(taken)
        return taken

    def last_span(self) -> Span:
        return self.tokens[self.index - 1].span if self.index else Span(1, 1, 1, 1)

    def error(self, message: str, expected: Iterable[str] = ()) -> QueryError:
        """Locate an error at the current token, or just after the last one."""
        token = self.current()
        if token is not None:
            line, column = token.span.line, token.span.column
        elif self.tokens:
            line, column = self.tokens[-1].span.end_line, self.tokens[-1].span.end_column
        else:
            line, column = 1, 1
        context = " ".join(token.text for token in self.tokens[max(0, self.index - 3) : self.index])
        if context:
            message += f" after '{context}'"
        return located_error(self.text, message, line, column, expected)

    def is_boundary(self, selections: bool = True) -> bool:
        """Whether the current token ends a run of noun words (``selections``: a selection phrase counts)."""
        word = self.word()
        if word is None or word == "with" or word in ANYWHERE_WORDS:
            return True
        if word in CONJUNCTIONS:
            return False
        return bool(
            self.match(PREPOSITIONS)
            or (selections and self.selection_phrase() is not None)
            or self.match(RELATIVE_CLAUSES)
            or word in SCAN_FOR
            or (self.match(TEXT_MARKERS) and self.text_after_marker() is not None)
        )

    def selection_phrase(self) -> tuple[str, ...] | None:
        """A selection phrase starting here (``on the left``) that no longer place phrase covers (``on top of``,
        ``to the left of``) and that ends the object phrase or is followed by another modifier (``on the left
        shelf`` is a place)."""
        found = self.match(SELECTION_PHRASES)
        if found is None:
            return None
        place = self.match(PREPOSITIONS)
        if place is not None and len(place) >= len(found):
            return None
        after = self.index + len(found)
        if after < len(self.tokens) and not self.is_boundary_after(len(found), selections=False):
            return None
        return found

    def is_boundary_after(self, ahead: int, selections: bool = True) -> bool:
        """Whether the token ``ahead`` of the current one ends a run of noun words."""
        self.index += ahead
        try:
            return self.is_boundary(selections)
        finally:
            self.index -= ahead

    def text_after_marker(self) -> PhraseToken | None:
        marker = self.match(TEXT_MARKERS)
        if marker is None:
            return None
        position = self.index + len(marker)
        if position < len(self.tokens) and self.tokens[position].kind == "string":
            return self.tokens[position]
        return None

    def whole_number(self, token: PhraseToken, what: str) -> Number:
        try:
            number = parse_quantity(token.text)
        except UnitError:
            number = None
        if number is None or number.unit is not None or not number.value.is_integer():
            raise self.error(f"expected a whole number as {what}")
        return number

    # -- the phrase -------------------------------------------------------

    def parse(self) -> Query:
        if not self.tokens:
            raise self.error("expected a phrase such as 'find the red cup'", VERB_EXAMPLES)
        while (filler := self.match(FILLERS)) is not None:
            self.take(len(filler))
        pointing = self.pointing_question()
        if pointing is not None:
            return pointing
        seen = self.what_is_question()
        if seen is not None:
            return seen
        counted = self.how_many_question()
        if counted is not None:
            return counted
        asked_key: str | None = None
        verb: tuple[str, ...] | None = None
        placement = self.match(PLACEMENT_VERBS)
        if placement is not None:
            verb_tokens = self.take(len(placement))
            kind_span = _join_span(verb_tokens[0].span, verb_tokens[-1].span)
            query = Query("scan", self.placement(kind_span), self.text, kind_span)
            validate_query(query)
            return query
        if self.word() == "what" and self.word(1) in QUESTION_ATTRIBUTES:
            verb_tokens = self.take(2)
            asked_key = QUESTION_ATTRIBUTES[verb_tokens[1].text]
            if self.word() in QUESTION_VERBS:
                self.take()
            kind = "inspect"
        else:
            verb = self.match(VERBS)
            if verb is None:
                raise self.error(
                    f"expected a verb such as {', '.join(VERB_EXAMPLES[:-1])} or stop{self.verb_guess()}",
                    VERB_EXAMPLES,
                )
            verb_tokens = self.take(len(verb))
            kind = VERBS[verb]
        kind_span = _join_span(verb_tokens[0].span, verb_tokens[-1].span)
        if kind == "stop":
            body = self.stop()
        elif kind == "scan":
            body = self.scan()
        else:
            watch = self.pointing_watch() if kind == "track" else None
            phrase = self.object_phrase()
            if asked_key is not None:
                phrase.extras.append(Field(asked_key, Asked(), kind_span))
            self.modifiers(phrase)
            self.expect_end()
            if kind == "detect" and phrase.noun in SCAN_TARGETS and not phrase.generic:
                kind = "scan"
                body = self.scan_body(None, phrase)
            else:
                body = self.object_body(kind, phrase)
            if watch is not None:
                body = Block((*body.fields, watch))
        query = Query(kind, body, self.text, kind_span, counted=kind == "detect" and verb in COUNT_VERBS)
        validate_query(query)
        return query

    def what_is_question(self) -> Query | None:
        """``what is on the table`` / ``what are the objects in the fridge``: a detect query for any object in the
        place; None (nothing consumed) when the phrase is no such question (``what is the colour of ...``)."""
        if self.word() != "what" or self.word(1) not in ("is", "are"):
            return None
        start = self.index
        verb_tokens = self.take(2)
        try:
            if self.match(PREPOSITIONS):
                phrase = _ObjectPhrase(self.tokens[self.index].span, self.tokens[self.index].span)
            else:
                phrase = self.object_phrase()
            self.modifiers(phrase)
            self.expect_end()
        except QueryError:
            phrase = None
        if phrase is None or (phrase.noun and not phrase.generic) or not phrase.locations:
            self.index = start
            return None
        phrase.limit_span = None
        kind_span = _join_span(verb_tokens[0].span, verb_tokens[-1].span)
        query = Query("detect", self.object_body("detect", phrase), self.text, kind_span)
        validate_query(query)
        return query

    def how_many_question(self) -> Query | None:
        """``how many cans are there (on the table)`` / ``how many cups do you see``: a detect query for every such
        object (the answer says how many and lists them); None when the phrase does not start with ``how many``."""
        opening = self.match(COUNT_QUESTIONS)
        if opening is None:
            return None
        verb_tokens = self.take(len(opening))
        start = self.index
        kept = list(self.tokens[:start])
        while self.current() is not None:
            tail = self.match(COUNT_TAILS)  # "are there", "do you see": the question's verb, not the object
            taken = self.take(len(tail) if tail is not None else 1)
            if tail is None:
                kept.extend(taken)
        self.tokens, self.index = kept, start
        phrase = self.object_phrase()
        self.modifiers(phrase)
        self.expect_end()
        if phrase.selection is not None and phrase.selection_span is not None:
            # "on the left" picks one object; a count takes every such object, so the two cannot both be meant
            raise self.error_at(
                phrase.selection_span,
                f"a count takes every such object, but '{phrase.selection}' picks one of them; "
                "ask with 'find' for that one",
            )
        phrase.limit, phrase.limit_span = None, None
        kind_span = _join_span(verb_tokens[0].span, verb_tokens[-1].span)
        query = Query("detect", self.object_body("detect", phrase), self.text, kind_span, counted=True)
        validate_query(query)
        return query

    def verb_guess(self) -> str:
        """``; did you mean 'find'?`` when the first word is a near miss of a one-word verb, else nothing."""
        word = self.word()
        if word is None:
            return ""
        if word == "how":  # "how" is no misspelt "show": the one how-question is a count
            return "; to count objects ask 'how many cups are there'"
        verbs = sorted({words[0] for words in VERBS if len(words) == 1})
        close = difflib.get_close_matches(word, verbs, n=1, cutoff=0.7)
        return f"; did you mean '{close[0]}'?" if close else ""

    def pointing_question(self) -> Query | None:
        """``which object is the person pointing at`` (also ``what ... point at``, ``which region / place ...``,
        ``where is the person pointing``): ``detect { pointing: { target: object | region } }``; None when the
        phrase is no such question."""
        words = [t.text for t in self.tokens if t.kind == "word"]
        if not words or words[0] not in POINTING_QUESTION_WORDS or not POINTING_VERBS & set(words):
            return None
        if not PERSON_WORDS & set(words):
            raise self.error("a pointing question names the person, e.g. 'which object is the person pointing at'")
        target = "region" if words[0] == "where" or REGION_WORDS & set(words) else "object"
        first, last = self.tokens[0].span, self.tokens[-1].span
        span = _join_span(first, last)
        block = Block((Field("target", Symbol(target), span),))
        query = Query("detect", Block((Field(POINTING_KEY, block, span),)), self.text, first)
        validate_query(query)
        return query

    def pointing_watch(self) -> Field | None:
        """``... and watch where she points`` after what a track follows (``... what she points at`` for an
        object target): the pointing block of ``track { human: {}, pointing: { target: ... } }``, its tokens
        cut off the phrase; None without such a tail."""
        for start in range(self.index, len(self.tokens) - 1):
            if self.tokens[start].text != "and" or self.tokens[start + 1].text not in WATCH_VERBS:
                continue
            tail = [t.text for t in self.tokens[start + 2 :] if t.kind == "word"]
            if not tail or tail[0] not in POINTING_QUESTION_WORDS or not POINTING_VERBS & set(tail):
                continue
            target = "region" if tail[0] == "where" or REGION_WORDS & set(tail) else "object"
            span = _join_span(self.tokens[start + 1].span, self.tokens[-1].span)
            self.tokens = self.tokens[:start]
            return Field(POINTING_KEY, Block((Field("target", Symbol(target), span),)), span)
        return None

    def expect_end(self) -> None:
        token = self.current()
        if token is not None:
            shown = token.text if token.kind != "string" else f'"{token.text}"'
            raise self.error(f"could not place '{shown}'")

    def object_body(self, kind: str, phrase: _ObjectPhrase) -> Block:
        self.check_rank(phrase)
        span = _join_span(phrase.start, phrase.end)
        fields = [Field("obj", phrase.block(), span)]
        selected = phrase.select_field()
        if selected is not None:
            fields.append(selected)
        if kind in ("detect", "track"):
            limit = phrase.limit
            if limit is None and phrase.limit_span is not None and not phrase.plural:
                limit = 1
            if limit is not None:
                fields.append(Field("max_results", Number(float(limit)), phrase.limit_span or span))
        return Block(tuple(fields))

    # -- object phrases ---------------------------------------------------

    def object_phrase(self) -> _ObjectPhrase:
        start = self.current()
        if start is None:
            raise self.error("expected an object")
        phrase = _ObjectPhrase(start.span, start.span)
        pronoun = self.word()
        if pronoun in PERSONAL_PRONOUNS and (self.index + 1 == len(self.tokens) or self.is_boundary_after(1)):
            token = self.take()[0]
            phrase.noun, phrase.noun_span, phrase.plural = PERSON_NOUN, token.span, not PERSONAL_PRONOUNS[pronoun]
            phrase.limit_span = token.span
            return phrase
        self.determiners(phrase, start)
        pronoun = self.word()
        if pronoun in INDEFINITE_PRONOUNS:
            token = self.take()[0]
            if INDEFINITE_PRONOUNS[pronoun] and phrase.limit is None:
                phrase.limit_span = phrase.limit_span or token.span
            phrase.noun, phrase.generic, phrase.noun_span = "object", True, token.span
            self.relative_adjectives(phrase, required=False)
            phrase.end = self.last_span()
            return phrase
        quoted = self.current()
        if quoted is not None and quoted.kind == "string":  # find "CHEEZ": whatever reads that text
            self.take()
            phrase.noun, phrase.generic, phrase.noun_span = "object", True, quoted.span
            phrase.extras.append(Field("text", String(quoted.text), quoted.span))
            phrase.end = quoted.span
            return phrase
        words: list[PhraseToken] = []
        while not self.is_boundary():
            words.append(self.take()[0])
        if not words:
            raise self.error("expected an object")
        number = self.current()
        if number is not None and number.kind == "number":
            if len(words) > 1 and words[-1].text in ID_MARKERS:
                words.pop()
            value = self.whole_number(number, "the object id")
            self.take()
            phrase.object_id = Field("id", value, number.span)
        self.noun_words(phrase, words)
        phrase.end = self.last_span()
        return phrase

    def determiners(self, phrase: _ObjectPhrase, start: PhraseToken) -> None:
        """Read the determiners before the noun: one (``the``, ``all``, ``two``, ``3``), or a quantity followed
        by another determiner, with or without ``of`` (``all the``, ``all of my``, ``one of the``, ``2 of these``),
        which then limits nothing itself."""
        word = self.word()
        quantity = True
        if word == "one" and self.word(1) == PARTITIVE_OF:
            phrase.limit = 1
            phrase.limit_span = self.take()[0].span
        elif word in LIMITING_DETERMINERS:
            phrase.limit_span = self.take()[0].span
            quantity = False
            after = self.current()  # ``the two biggest bowls``, ``these 3 cups``: the quantity sets the limit
            if after is not None and after.kind == "word" and after.text in COUNT_WORDS:
                phrase.limit, phrase.limit_span = COUNT_WORDS[after.text], self.take()[0].span
            elif after is not None and after.kind == "number" and not self.is_boundary_after(1):
                phrase.limit = int(self.whole_number(after, "the number of objects").value)
                phrase.limit_span = self.take()[0].span
        elif word in OPEN_DETERMINERS:
            self.take()
        elif word is not None and word in COUNT_WORDS:
            phrase.limit = COUNT_WORDS[word]
            phrase.limit_span = self.take()[0].span
        elif start.kind == "number":
            phrase.limit = int(self.whole_number(start, "the number of objects").value)
            phrase.limit_span = self.take()[0].span
        else:
            quantity = False
        if not quantity:
            return
        if self.word() == PARTITIVE_OF and self.word(1) in LIMITING_DETERMINERS:
            self.take()
        if self.word() in LIMITING_DETERMINERS:
            self.take()

    def noun_words(self, phrase: _ObjectPhrase, words: list[PhraseToken]) -> None:
        """Split words into adjectives and the (possibly compound) head noun."""
        head = words[-1]
        if head.text in CONJUNCTIONS:
            raise self.error_at(head.span, f"expected a noun, not '{head.text}'")
        nouns: list[str] = []
        position = 0
        before = words[:-1]
        while position < len(before):
            token = before[position]
            word = token.text
            following = before[position + 1].text if position + 1 < len(before) else None
            if word in COLOR_MODIFIERS and following is not None and following in COLORS:
                phrase.add_adjective("color", Symbol(f"{word}_{COLORS[following]}"), token.span)
                position += 2
                continue
            if word in ORDINALS and phrase.rank_span is None and not nouns:
                phrase.rank, phrase.rank_span = ORDINALS[word], token.span
                position += 1
                continue
            if word in SELECTION_WORDS and not nouns:
                self.select(phrase, SELECTION_WORDS[word], token.span)
                position += 1
                continue
            if word in CONJUNCTIONS:
                if position == 0 or following is None or not self.is_adjective(following):
                    raise self.error_at(
                        token.span,
                        f"expected one object: '{word}' can only join colours, sizes or shapes",
                    )
                position += 1
                continue
            if not self.add_adjective_word(phrase, word, token.span):
                nouns.append(word)
            position += 1
        if head.text in SELECTION_WORDS and not nouns:  # ``find the highest``: the highest object
            self.select(phrase, SELECTION_WORDS[head.text], head.span)
            phrase.generic, phrase.noun, phrase.noun_span = True, "object", head.span
            return
        singular, plural = singularise(head.text)
        phrase.plural = plural
        if not nouns and singular in SHAPE_NOUNS:
            phrase.add_adjective("shape", Symbol(SHAPE_NOUNS[singular]), head.span)
            singular = "object"
        phrase.generic = not nouns and singular in GENERIC_NOUNS
        if phrase.generic and phrase.selection is not None:  # ``the biggest one``: the biggest object
            singular = "object"
        phrase.noun = "_".join([*nouns, singular])
        first = next((token for token in before if token.text in nouns), head)
        phrase.noun_span = _join_span(first.span, head.span)

    def select(self, phrase: _ObjectPhrase, selection: str, span: Span) -> None:
        """Record a selection in ``phrase``; a second, different one is an error located at ``span``."""
        try:
            phrase.select(selection, span)
        except ValueError as error:
            raise self.error_at(span, str(error)) from None

    def check_rank(self, phrase: _ObjectPhrase) -> None:
        """An ordinal needs a selection to count in: ``the second biggest``, ``the second from the left``."""
        if phrase.rank_span is not None and phrase.selection is None:
            raise self.error_at(
                phrase.rank_span,
                "an ordinal counts along a selection, e.g. 'the second biggest box' or 'the second box from the left'",
            )

    @staticmethod
    def is_adjective(word: str) -> bool:
        return word in COLOR_MODIFIERS or any(word in table for _, table in ADJECTIVE_KEYS)

    @staticmethod
    def add_adjective_word(phrase: _ObjectPhrase, word: str, span: Span) -> bool:
        for key, table in ADJECTIVE_KEYS:
            if word in table:
                phrase.add_adjective(key, Symbol(table[word]), span)
                return True
        return False

    def modifiers(self, phrase: _ObjectPhrase) -> None:
        """Read place, text, relative-clause and ``with`` phrases after the noun."""
        while (token := self.current()) is not None:
            if token.kind == "string":
                self.take()
                phrase.extras.append(Field("text", String(token.text), token.span))
            elif (quoted := self.text_after_marker()) is not None:
                marker = self.take(len(self.match(TEXT_MARKERS) or ()))
                self.take()
                span = _join_span(marker[0].span, quoted.span)
                phrase.extras.append(Field("text", String(quoted.text), span))
            elif (selecting := self.selection_phrase()) is not None:
                taken = self.take(len(selecting))
                self.select(phrase, SELECTION_PHRASES[selecting], _join_span(taken[0].span, taken[-1].span))
            elif (preposition := self.match(PREPOSITIONS)) is not None:
                if phrase.anywhere is not None:
                    raise self.error("expected one place: 'anywhere' lifts the place restriction")
                taken = self.take(len(preposition))
                place, place_span = self.place_phrase()
                span = _join_span(taken[0].span, place_span)
                phrase.locations.append(Field(PREPOSITIONS[preposition], place, span))
                first = phrase.location_span or span
                phrase.location_span = _join_span(first, span)
            elif (clause := self.match(RELATIVE_CLAUSES)) is not None:
                self.take(len(clause))
                self.relative_adjectives(phrase)
            elif self.word() in ANYWHERE_WORDS:
                if phrase.locations or phrase.anywhere is not None:
                    raise self.error("expected one place: 'anywhere' lifts the place restriction")
                phrase.anywhere = self.take()[0].span
            elif self.word() == "with":
                taken = self.take()
                place, place_span = self.place_phrase()
                phrase.extras.append(Field("with", place, _join_span(taken[0].span, place_span)))
            else:
                break
            phrase.end = self.last_span()

    def relative_adjectives(self, phrase: _ObjectPhrase, required: bool = True) -> None:
        """Read colours, sizes, shapes and properties joined by conjunctions (at least one when ``required``)."""
        found = False
        while (word := self.word()) is not None:
            if word in CONJUNCTIONS and found:
                self.take()
                continue
            following = self.word(1)
            if word in COLOR_MODIFIERS and following is not None and following in COLORS:
                tokens = self.take(2)
                value = Symbol(f"{word}_{COLORS[following]}")
                phrase.add_adjective("color", value, tokens[0].span)
            elif not self.add_adjective_word(phrase, word, self.tokens[self.index].span):
                break
            else:
                self.take()
            found = True
        if not found and required:
            raise self.error("expected a colour, size or shape")

    def place_phrase(self) -> tuple[Symbol, Span]:
        """Read the noun phrase after a preposition as one symbol."""
        word = self.word()
        if word in LIMITING_DETERMINERS or word in OPEN_DETERMINERS:
            self.take()
        words: list[PhraseToken] = []
        while not self.is_boundary():
            if self.word() in CONJUNCTIONS:
                break
            words.append(self.take()[0])
        if not words:
            raise self.error("expected a place")
        singular, _ = singularise(words[-1].text)
        name = "_".join([*(token.text for token in words[:-1]), singular])
        return Symbol(name), _join_span(words[0].span, words[-1].span)

    # -- scan and stop ----------------------------------------------------

    def scan(self) -> Block:
        region: Field | None = None
        word = self.word()
        if word is not None and word not in SCAN_FOR and not self.match(PREPOSITIONS):
            place, span = self.place_phrase()
            region = Field("region", place, span)
        phrase = _ObjectPhrase(self.last_span(), self.last_span())
        if self.word() in SCAN_FOR:
            self.take()
            target, span = self.place_phrase()
            phrase.noun = target.name
            phrase.noun_span = span
        self.modifiers(phrase)
        self.expect_end()
        return self.scan_body(region, phrase)

    def scan_body(self, region: Field | None, phrase: _ObjectPhrase) -> Block:
        if phrase.adjectives or phrase.extras or phrase.object_id is not None:
            raise self.error_at(phrase.start, "expected only a region and what to scan for")
        for place in phrase.locations:
            if region is not None:
                raise self.error_at(place.span, "expected one region to scan")
            region = Field("region", place.value, place.span)
        fields = [] if region is None else [region]
        if phrase.noun:
            target = Symbol(SCAN_TARGETS.get(phrase.noun, phrase.noun))
            fields.append(Field("for", target, phrase.noun_span or phrase.start))
        return Block(tuple(fields))

    def placement(self, verb_span: Span) -> Block:
        """``where can I put the cup on the shelf``: what to put (a class) and where, as a free-space block."""
        phrase = self.object_phrase()
        self.modifiers(phrase)
        self.expect_end()
        if phrase.adjectives or phrase.extras or phrase.object_id is not None or phrase.anywhere is not None:
            raise self.error_at(phrase.start, "expected only what to put (an object class) and where")
        if len(phrase.locations) > 1:
            raise self.error_at(phrase.locations[1].span, "expected one place to put it")
        fields = [Field("region", place.value, place.span) for place in phrase.locations]
        if phrase.noun and not phrase.generic:
            fields.append(Field("for", Symbol(phrase.noun), phrase.noun_span or phrase.start))
        if not fields:
            raise self.error_at(phrase.start, "expected what to put (an object class) or where")
        span = _join_span(verb_span, phrase.end)
        return Block((Field(FREE_SPACE_KEY, Block(tuple(fields)), span),))

    def error_at(self, span: Span, message: str) -> QueryError:
        return located_error(self.text, message, span.line, span.column)

    def stop(self) -> Block:
        while self.word() in STOP_TASK_WORDS:
            self.take()
        token = self.current()
        fields: list[Field] = []
        if token is not None and token.kind == "number":
            fields.append(Field("task", self.whole_number(token, "the task"), token.span))
            self.take()
        elif token is not None and token.text in STOP_ALL_WORDS and token.kind == "word":
            fields.append(Field("task", Symbol(STOP_ALL_WORDS[token.text]), token.span))
            self.take()
        self.expect_end()
        return Block(tuple(fields))


POINTING_QUESTION_WORDS = frozenset({"which", "what", "where"})
POINTING_VERBS = frozenset({"pointing", "point", "points", "pointed", "gesturing"})
PERSON_WORDS = frozenset({"person", "human", "man", "woman", "someone", "somebody", "she", "he", "they", "people"})
REGION_WORDS = frozenset({"region", "place", "area", "storage", "location", "shelf", "counter"})
WATCH_VERBS = frozenset({"watch", "see", "check", "notice", "tell"})
"""Verbs joining a pointing question to a track phrase (``follow the person and watch where she points``)."""


def parse_natural(text: str) -> Query:
    """Parse and validate a short English phrase; raise :class:`QueryError`."""
    check_length(text, MAX_QUERY_LENGTH)
    return _PhraseParser(text, tokenize_phrase(text)).parse()
