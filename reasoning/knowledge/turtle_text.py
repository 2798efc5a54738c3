"""Editing a Turtle file as text, so that everything an edit does not touch stays byte for byte.

:func:`split_statements` cuts a Turtle document into its top-level statements (triples ending in ``.`` and prefix or
base directives); comments and blank lines between them belong to no statement. :func:`edit_turtle` removes folded
triples (:mod:`reasoning.knowledge.folded_triples`) by deleting the statements that hold only those triples and
rewriting (re-serialising) the few that hold others too, and appends added triples as one block between marker
comments. The result is parsed and must mean exactly the old document minus the removed plus the added triples;
otherwise :class:`TextEditError` is raised and nothing is changed. An emptied marker block is deleted with its
markers; comments and statements the edit does not touch are kept in place.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from itertools import groupby

from rdflib import Graph, Literal, URIRef

from reasoning.knowledge.folded_triples import Folded, FoldedTriple, NotFoldableError, Tree, fold
from reasoning.knowledge.vocabulary import OWL, RDF, RDFS, RK, SKOS, XSD

STANDARD_PREFIXES: Mapping[str, str] = {
    "rk": str(RK),
    "owl": str(OWL),
    "rdf": str(RDF),
    "rdfs": str(RDFS),
    "skos": str(SKOS),
    "xsd": str(XSD),
}
"""The prefixes blocks written by the editor use."""

BLOCK_START = "# >>> robokudo edit"
BLOCK_END = "# <<< robokudo edit"

_SPARQL_PREFIX = re.compile(r"(?i)PREFIX\s+([A-Za-z][\w.-]*)?:\s*<([^>]*)>")
_SPARQL_BASE = re.compile(r"(?i)BASE\s+<([^>]*)>")
_TURTLE_PREFIX = re.compile(r"@prefix\s+([A-Za-z][\w.-]*)?:\s*<([^>]*)>\s*\.\Z")
_TURTLE_BASE = re.compile(r"@base\s+<([^>]*)>\s*\.\Z")
_EMPTY_BLOCK = re.compile(
    rf"(?m)(^[ \t]*\n)?^{re.escape(BLOCK_START)} (\d+)\b[^\n]*\n(?:[ \t]*\n)*"
    rf"^{re.escape(BLOCK_END)} \2\b[^\n]*(?:\n|\Z)"
)


class TextEditError(ValueError):
    """A Turtle document could not be edited as text without changing other triples."""


@dataclass(frozen=True)
class Statement:
    """A top-level statement: ``text[start:end]``; ``prefix`` / ``base`` are set for directives."""

    start: int
    end: int
    prefix: tuple[str, str] | None = None
    base: str | None = None

    @property
    def is_directive(self) -> bool:
        """True for a prefix or base directive."""
        return self.prefix is not None or self.base is not None


def split_statements(text: str) -> list[Statement]:
    """The top-level statements of a Turtle document, in order (a trailing unterminated one included)."""
    statements: list[Statement] = []
    length = len(text)
    i = 0
    start: int | None = None
    depth = 0
    while i < length:
        char = text[i]
        if char == "#":
            newline = text.find("\n", i)
            i = length if newline < 0 else newline + 1
            continue
        if char.isspace():
            i += 1
            continue
        if start is None:
            start = i
            directive = _SPARQL_PREFIX.match(text, i) or _SPARQL_BASE.match(text, i)
            if directive is not None:
                if directive.re is _SPARQL_PREFIX:
                    statement = Statement(i, directive.end(), prefix=(directive[1] or "", directive[2]))
                else:
                    statement = Statement(i, directive.end(), base=directive[1])
                statements.append(statement)
                i, start = directive.end(), None
                continue
        if char == "<":
            close = text.find(">", i + 1)
            i = length if close < 0 else close + 1
            continue
        if char in "\"'":
            i = _string_end(text, i)
            continue
        if char in "[(":
            depth += 1
        elif char in "])":
            depth -= 1
        elif char == "." and depth == 0 and (i + 1 >= length or text[i + 1].isspace() or text[i + 1] in "#<[(\"'"):
            statements.append(_statement(text, start, i + 1))
            start = None
        i += 1
    if start is not None:
        statements.append(Statement(start, length))
    return statements


def _string_end(text: str, i: int) -> int:
    """The index after the string literal starting at ``i``."""
    quote = text[i]
    if text.startswith(quote * 3, i):
        j = i + 3
        while j < len(text):
            if text[j] == "\\":
                j += 2
            elif text.startswith(quote * 3, j):
                return j + 3
            else:
                j += 1
        return len(text)
    j = i + 1
    while j < len(text):
        if text[j] == "\\":
            j += 2
        elif text[j] == quote or text[j] == "\n":
            return j + 1
        else:
            j += 1
    return len(text)


def _statement(text: str, start: int, end: int) -> Statement:
    body = text[start:end]
    prefix = _TURTLE_PREFIX.match(body)
    if prefix is not None:
        return Statement(start, end, prefix=(prefix[1] or "", prefix[2]))
    base = _TURTLE_BASE.match(body)
    if base is not None:
        return Statement(start, end, base=base[1])
    return Statement(start, end)


def prefixes_at_end(text: str) -> dict[str, str]:
    """The prefix -> namespace bindings in effect at the end of a Turtle document."""
    bound: dict[str, str] = {}
    for statement in split_statements(text):
        if statement.prefix is not None:
            bound[statement.prefix[0]] = statement.prefix[1]
    return bound


def parse(text: str, base: str) -> Graph:
    """Parse Turtle ``text`` whose relative IRIs resolve against ``base``; ValueError with rdflib's message."""
    graph = Graph()
    try:
        graph.parse(data=text, format="turtle", publicID=base)
    except Exception as error:  # rdflib raises several unrelated types for syntax errors
        raise ValueError(f"not valid Turtle: {error}") from None
    return graph


def edit_turtle(
    text: str,
    base: str,
    removed: frozenset[FoldedTriple],
    added: frozenset[FoldedTriple],
    heading: str,
    number: int,
) -> str:
    """``text`` without the ``removed`` triples and with the ``added`` ones appended as block ``number``.

    ``heading`` follows the block's start marker (one line). TextEditError when the document cannot be edited so
    (a removed triple is not found, a blank node is shared between statements, ...); the result is verified by
    parsing.
    """
    try:
        before = fold(parse(text, base))
    except NotFoldableError as error:
        raise TextEditError(f"the file cannot be edited triple by triple: {error}") from None
    missing = removed - before
    if missing:
        raise TextEditError(f"{len(missing)} triple(s) to remove are not in the file")
    edited = _remove(text, base, removed) if removed else text
    new_added = added - (before - removed)
    if new_added:
        edited = _append(edited, new_added, heading.replace("\n", " "), number)
    try:
        after = fold(parse(edited, base))
    except (ValueError, NotFoldableError) as error:
        raise TextEditError(f"the edited file would not be read back as intended: {error}") from None
    if after != (before - removed) | added:
        raise TextEditError("the edited file would not hold exactly the intended triples")
    return edited


def _remove(text: str, base: str, removed: frozenset[FoldedTriple]) -> str:
    """Delete or rewrite the statements holding ``removed`` triples."""
    names = {_local(s) for s, _, _ in removed if s is not None}
    anonymous = any(s is None for s, _, _ in removed)
    context: list[str] = []
    bound: dict[str, str] = {}
    replacements: list[tuple[int, int, str]] = []
    found: set[FoldedTriple] = set()
    for statement in split_statements(text):
        body = text[statement.start : statement.end]
        if statement.is_directive:
            context.append(body)
            if statement.prefix is not None:
                bound[statement.prefix[0]] = statement.prefix[1]
            continue
        if not anonymous and not any(name in body for name in names):
            continue
        try:
            triples = fold(parse("\n".join([*context, body]), base))
        except (ValueError, NotFoldableError):
            continue  # the final check reports what could not be removed
        hit = triples & removed
        if not hit:
            continue
        found |= hit
        if hit == triples:
            start, end = _line_span(text, statement.start, statement.end)
            replacements.append((start, end, ""))
        else:
            replacements.append((statement.start, statement.end, _serialize(triples - hit, bound)[1]))
    if found != removed:
        raise TextEditError(
            f"{len(removed - found)} triple(s) to remove could not be found statement by statement in the file"
        )
    for start, end, replacement in sorted(replacements, reverse=True):
        text = text[:start] + replacement + text[end:]
    return _EMPTY_BLOCK.sub("", text)


def _local(subject: object) -> str:
    text = str(subject)
    return re.split(r"[#/:]", text)[-1] or text


def _line_span(text: str, start: int, end: int) -> tuple[int, int]:
    """Widen a statement's span to whole lines when only blanks share its first and last line."""
    line_start = text.rfind("\n", 0, start) + 1
    if text[line_start:start].strip():
        line_start = start
    line_end = text.find("\n", end)
    line_end = len(text) if line_end < 0 else line_end + 1
    if text[end:line_end].strip():
        return line_start, end
    return line_start, line_end


def _serialize(triples: Iterable[FoldedTriple], prefixes: Mapping[str, str]) -> tuple[dict[str, str], str]:
    """Turtle for ``triples`` with prefixed names for ``prefixes``: one statement per subject, its type first, blank
    nodes inline. Returns the prefixes the text uses and the text."""
    writer = _Writer(prefixes)
    by_subject: dict[object, list[tuple[URIRef, Folded]]] = defaultdict(list)
    anonymous: list[Tree] = []
    for subject, predicate, obj in triples:
        if subject is None or predicate is None:
            anonymous.append(obj)  # type: ignore[arg-type]
        else:
            by_subject[subject].append((predicate, obj))
    statements = []
    for subject in sorted(by_subject, key=str):
        pairs = sorted(by_subject[subject], key=lambda pair: (_ORDER.get(pair[0], len(_ORDER)), str(pair[0])))
        lines: list[str] = []
        for predicate, group in groupby(pairs, key=lambda pair: pair[0]):
            objects = sorted((writer.term(obj) for _, obj in group), key=lambda text: (text.startswith("["), text))
            lines.append(f"{writer.predicate(predicate)} " + " ,\n        ".join(objects))
        statements.append(writer.term(subject) + " " + " ;\n    ".join(lines) + " .")
    statements += sorted(writer.term(tree) + " ." for tree in anonymous)
    return writer.used, "\n".join(statements)


_ORDER = {RDF.type: 0, RDFS.subClassOf: 1, OWL.equivalentClass: 2, RDFS.label: 3, SKOS.altLabel: 4}
_LOCAL = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")
_PLAIN_LITERALS = {
    XSD.boolean: re.compile(r"true|false"),
    XSD.integer: re.compile(r"[+-]?[0-9]+"),
    XSD.decimal: re.compile(r"[+-]?[0-9]*\.[0-9]+"),
    XSD.double: re.compile(r"[+-]?(?:[0-9]+\.[0-9]*|\.?[0-9]+)[eE][+-]?[0-9]+"),
}


class _Writer:
    """Turtle terms with prefixed names where a bound prefix fits; remembers the prefixes used."""

    def __init__(self, prefixes: Mapping[str, str]) -> None:
        self.prefixes = sorted(prefixes.items(), key=lambda item: -len(item[1]))
        self.used: dict[str, str] = {}

    def predicate(self, predicate: URIRef) -> str:
        return "a" if predicate == RDF.type else self.term(predicate)

    def term(self, value: object) -> str:
        if isinstance(value, Tree):
            return self._tree(value)
        if isinstance(value, Literal):
            plain = _PLAIN_LITERALS.get(value.datatype)
            if plain is not None and plain.fullmatch(str(value)):
                return str(value)
            if value.datatype is not None:
                return f"{value.n3().split('^^')[0]}^^{self.term(value.datatype)}"
            return value.n3()
        text = str(value)
        for prefix, namespace in self.prefixes:
            local = text[len(namespace) :]
            if text.startswith(namespace) and _LOCAL.fullmatch(local):
                self.used[prefix] = namespace
                return f"{prefix}:{local}"
        return f"<{text}>"

    def _tree(self, tree: Tree) -> str:
        items = _list_items(tree)
        if items is not None:
            return "( " + " ".join(self.term(item) for item in items) + " )"
        pairs = sorted(tree, key=lambda pair: (_ORDER.get(pair[0], len(_ORDER)), str(pair[0]), str(pair[1])))
        return "[ " + " ; ".join(f"{self.predicate(p)} {self.term(o)}" for p, o in pairs) + " ]"


def _list_items(tree: Tree) -> list[Folded] | None:
    """The members of an RDF list, or None when ``tree`` is not a list cell."""
    items: list[Folded] = []
    cell: Folded = tree
    while isinstance(cell, Tree):
        values = dict(cell)
        if set(values) != {RDF.first, RDF.rest} or len(cell) != 2:
            return None
        items.append(values[RDF.first])
        cell = values[RDF.rest]
    return items if cell == RDF.nil else None


def _append(text: str, added: Iterable[FoldedTriple], heading: str, number: int) -> str:
    bound = prefixes_at_end(text)
    used, body = _serialize(added, {**STANDARD_PREFIXES, **bound})
    declarations = "".join(f"@prefix {p}: <{iri}> .\n" for p, iri in sorted(used.items()) if bound.get(p) != iri)
    if text and not text.endswith("\n"):
        text += "\n"
    return f"{text}\n{BLOCK_START} {number}: {heading}\n{declarations}{body}\n{BLOCK_END} {number}\n"
