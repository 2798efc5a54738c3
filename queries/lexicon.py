"""Word tables for natural phrasing (data only: no object names live here).

Multi-word entries are tuples of lower-case words; the phrase parser uses
the longest match.  Words not in these tables are left as they are (joined
with underscores) for the reasoning layer to resolve against the ontology.
"""

from __future__ import annotations

from types import MappingProxyType

VERBS: MappingProxyType[tuple[str, ...], str] = MappingProxyType(
    {
        ("find",): "detect",
        ("find", "me"): "detect",
        ("get", "me"): "detect",
        ("detect",): "detect",
        ("locate",): "detect",
        ("get",): "detect",
        ("search",): "detect",
        ("search", "for"): "detect",
        ("look", "for"): "detect",
        ("where", "is"): "detect",
        ("where", "are"): "detect",
        ("is", "there"): "detect",
        ("are", "there"): "detect",
        ("show", "me"): "detect",
        ("show",): "detect",
        ("list",): "detect",
        ("see",): "detect",
        ("do", "you", "see"): "detect",
        ("recognize",): "detect",
        ("recognise",): "detect",
        ("identify",): "detect",
        ("count",): "detect",
        ("track",): "track",
        ("follow",): "track",
        ("keep", "track", "of"): "track",
        ("inspect",): "inspect",
        ("examine",): "inspect",
        ("look", "at"): "inspect",
        ("check",): "inspect",
        ("scan",): "scan",
        ("stop",): "stop",
        ("cancel",): "stop",
        ("abort",): "stop",
    }
)
"""Verb phrases and the query kind they start."""

PLACEMENT_VERBS: frozenset[tuple[str, ...]] = frozenset(
    (opening, modal, person, verb)
    for opening in ("where",)
    for modal in ("can", "could", "should", "do", "may")
    for person in ("i", "we", "you")
    for verb in ("put", "place", "set", "leave", "store")
)
"""``where can I put X on Y``: a free-space scan for X's footprint in region Y."""

QUESTION_ATTRIBUTES: MappingProxyType[str, str] = MappingProxyType(
    {"color": "color", "colour": "color", "size": "size", "shape": "shape"}
)
"""``what <attribute> is the X`` asks for this key of an ``inspect`` query."""

COUNT_QUESTIONS: frozenset[tuple[str, ...]] = frozenset({("how", "many")})
"""Openings of a question for every object of a kind: ``how many cans are there``."""

COUNT_VERBS: frozenset[tuple[str, ...]] = frozenset({("count",)})
"""Verbs (of :data:`VERBS`) that ask how many: ``count the bowls`` is answered with the number, as ``how many``."""

COUNT_TAILS: frozenset[tuple[str, ...]] = frozenset(
    {
        ("are", "there"),
        ("is", "there"),
        ("there", "are"),
        ("there", "is"),
        ("do", "you", "see"),
        ("can", "you", "see"),
        ("you", "see"),
        ("do", "i", "have"),
        ("are", "visible"),
        ("are", "left"),
        ("are",),
        ("is",),
    }
)
"""The verb of a ``how many`` question, wherever it stands (``how many cans are there on the table``, ``how many
cups are on the table``)."""

QUESTION_VERBS: frozenset[str] = frozenset({"is", "are", "does", "do"})
"""Words allowed between ``what <attribute>`` and the object."""

FILLERS: frozenset[tuple[str, ...]] = frozenset(
    {
        ("please",),
        ("robot",),
        ("hey",),
        ("kindly",),
        ("can", "you"),
        ("could", "you"),
        ("would", "you"),
        ("will", "you"),
        ("i", "want", "you", "to"),
        ("try", "to"),
    }
)
"""Polite openings skipped before the verb."""

IGNORED_WORDS: frozenset[str] = frozenset({"please", "thanks"})
"""Words skipped anywhere in a phrase."""

LIMITING_DETERMINERS: frozenset[str] = frozenset(
    {"a", "an", "the", "this", "that", "these", "those", "one", "my", "your", "our", "his", "her", "their"}
)
"""Determiners that, before a singular noun, ask for one result."""

OPEN_DETERMINERS: frozenset[str] = frozenset({"some", "any", "all", "every", "each"})
"""Determiners that set no result limit."""

PARTITIVE_OF: str = "of"
"""The word of ``all of the cups`` / ``two of the mugs``: after a quantity, it and a determiner are skipped."""

COUNT_WORDS: MappingProxyType[str, int] = MappingProxyType(
    {
        "both": 2,
        "two": 2,
        "three": 3,
        "four": 4,
        "five": 5,
        "six": 6,
        "seven": 7,
        "eight": 8,
        "nine": 9,
        "ten": 10,
    }
)
"""Number words that set ``max_results`` (``one`` limits as a determiner; ``one of the`` sets 1)."""

COLORS: MappingProxyType[str, str] = MappingProxyType(
    {
        "red": "red",
        "green": "green",
        "blue": "blue",
        "yellow": "yellow",
        "orange": "orange",
        "purple": "purple",
        "violet": "violet",
        "pink": "pink",
        "white": "white",
        "black": "black",
        "grey": "gray",
        "gray": "gray",
        "brown": "brown",
        "silver": "silver",
        "gold": "gold",
        "golden": "gold",
        "teal": "teal",
        "cyan": "cyan",
        "magenta": "magenta",
        "beige": "beige",
        "turquoise": "turquoise",
    }
)
"""Colour adjectives and the ``color`` value they give."""

TRANSPARENCY: MappingProxyType[str, str] = MappingProxyType(
    {"transparent": "true", "clear": "true", "translucent": "true", "opaque": "false"}
)
"""Adjectives of the ``transparent`` property (a property of the object, not a colour): ``transparent: true``."""

COLOR_MODIFIERS: frozenset[str] = frozenset({"light", "dark", "bright", "pale"})
"""Words joined to a following colour: ``dark red`` -> ``dark_red``."""

SIZES: MappingProxyType[str, str] = MappingProxyType(
    {
        "tiny": "tiny",
        "small": "small",
        "little": "small",
        "medium": "medium",
        "large": "large",
        "big": "large",
        "huge": "large",
    }
)
"""Size adjectives and the ``size`` value they give."""

SELECTION_WORDS: MappingProxyType[str, str] = MappingProxyType(
    {
        "top": "top",
        "topmost": "top",
        "uppermost": "top",
        "upper": "top",
        "highest": "top",
        "bottom": "bottom",
        "bottommost": "bottom",
        "lowest": "bottom",
        "lower": "bottom",
        "leftmost": "leftmost",
        "left": "leftmost",
        "rightmost": "rightmost",
        "right": "rightmost",
        "closest": "closest",
        "nearest": "closest",
        "closer": "closest",
        "nearer": "closest",
        "farthest": "farthest",
        "furthest": "farthest",
        "biggest": "biggest",
        "largest": "biggest",
        "hugest": "biggest",
        "bigger": "biggest",
        "larger": "biggest",
        "smallest": "smallest",
        "tiniest": "smallest",
        "littlest": "smallest",
        "smaller": "smallest",
    }
)
"""Words before the noun that pick objects by a relation among those found (``the top box``, ``the biggest
bowl``) and the selection they name (:data:`queries.selection.SELECTIONS`); the comparative (``the bigger one``)
picks the same way."""

SELECTION_PHRASES: MappingProxyType[tuple[str, ...], str] = MappingProxyType(
    {
        ("on", "the", "left"): "leftmost",
        ("on", "the", "right"): "rightmost",
        ("at", "the", "left"): "leftmost",
        ("at", "the", "right"): "rightmost",
        ("to", "the", "left"): "leftmost",
        ("to", "the", "right"): "rightmost",
        ("from", "the", "left"): "leftmost",
        ("from", "the", "right"): "rightmost",
        ("on", "top"): "top",
        ("at", "the", "top"): "top",
        ("from", "the", "top"): "top",
        ("at", "the", "bottom"): "bottom",
        ("from", "the", "bottom"): "bottom",
    }
)
"""Phrases after the noun that select the same way (``the box on the left``, ``the second cup from the left``); a
longer place phrase wins (``on top of the shelf`` is a place, ``to the left of the cup`` a relation to it)."""

ORDINALS: MappingProxyType[str, int] = MappingProxyType(
    {
        "first": 1,
        "second": 2,
        "third": 3,
        "fourth": 4,
        "fifth": 5,
        "sixth": 6,
        "seventh": 7,
        "eighth": 8,
        "ninth": 9,
        "tenth": 10,
    }
)
"""Ordinals before a selection give its rank: ``the second biggest bowl`` -> ``select: { by: biggest, rank: 2 }``."""

SHAPES: MappingProxyType[str, str] = MappingProxyType(
    {
        "round": "sphere",
        "spherical": "sphere",
        "cylindrical": "cylinder",
        "boxy": "box",
        "rectangular": "box",
        "cuboid": "box",
        "conical": "cone",
        "flat": "flat",
    }
)
"""Shape adjectives and the ``shape`` value they give."""

SHAPE_NOUNS: MappingProxyType[str, str] = MappingProxyType(
    {"box": "box", "cuboid": "box", "cube": "box", "cylinder": "cylinder", "sphere": "sphere"}
)
"""Head nouns that name a shape, not a class: ``a small red cylinder`` -> ``shape: cylinder`` and no ``type``
(a compound such as ``cereal box`` stays a class)."""

PERSONAL_PRONOUNS: MappingProxyType[str, bool] = MappingProxyType(
    {"me": True, "him": True, "her": True, "us": False, "them": False}
)
"""Pronouns that, standing alone as the object (``follow me``), mean a person; True when they mean one."""

PERSON_NOUN = "person"
"""The noun a personal pronoun stands for."""

INDEFINITE_PRONOUNS: MappingProxyType[str, bool] = MappingProxyType(
    {"something": True, "anything": False, "everything": False}
)
"""Pronouns standing for any object, followed by adjectives (``something blue``); True when they ask for one."""

ADJECTIVE_KEYS: tuple[tuple[str, MappingProxyType[str, str]], ...] = (
    ("color", COLORS),
    ("size", SIZES),
    ("shape", SHAPES),
    ("transparent", TRANSPARENCY),
)
"""Which key each adjective table fills, in the order keys are written."""

CONJUNCTIONS: frozenset[str] = frozenset({"and", "or"})
"""Words that may join adjectives: ``red and white cup``."""

PREPOSITIONS: MappingProxyType[tuple[str, ...], str] = MappingProxyType(
    {
        ("in",): "in",
        ("inside",): "in",
        ("inside", "of"): "in",
        ("into",): "in",
        ("within",): "in",
        ("on",): "on",
        ("onto",): "on",
        ("upon",): "on",
        ("on", "top", "of"): "on",
        ("at",): "at",
        ("near",): "near",
        ("next", "to"): "near",
        ("beside",): "near",
        ("by",): "near",
        ("under",): "under",
        ("below",): "under",
        ("beneath",): "under",
        ("underneath",): "under",
        ("behind",): "behind",
        ("in", "front", "of"): "in_front_of",
        ("above",): "above",
        ("over",): "above",
        ("left", "of"): "left_of",
        ("to", "the", "left", "of"): "left_of",
        ("right", "of"): "right_of",
        ("to", "the", "right", "of"): "right_of",
    }
)
"""Prepositions and the key they give inside ``location: { ... }``."""

ANYWHERE_WORDS: frozenset[str] = frozenset({"anywhere", "everywhere"})
"""Words that lift any place restriction: ``find milk anywhere`` -> ``location: anywhere``."""

TEXT_MARKERS: frozenset[tuple[str, ...]] = frozenset(
    {
        ("with",),
        ("with", "the", "text"),
        ("with", "text"),
        ("with", "the", "label"),
        ("with", "label"),
        ("with", "the", "words"),
        ("labelled",),
        ("labeled",),
        ("saying",),
        ("reading",),
        ("marked",),
        ("named",),
        ("called",),
    }
)
"""Words that may introduce quoted text: ``a milk with "lactose free"``."""

RELATIVE_CLAUSES: frozenset[tuple[str, ...]] = frozenset(
    {("that", "is"), ("that", "are"), ("which", "is"), ("which", "are")}
)
"""Openings of ``the cup that is red``: adjectives may follow."""

GENERIC_NOUNS: frozenset[str] = frozenset({"object", "item", "thing", "one"})
"""Nouns that name no class; they set no ``type`` unless nothing else is said."""

ID_MARKERS: frozenset[str] = frozenset({"number", "no", "id"})
"""Words allowed between a noun and its id: ``object number 12``."""

SCAN_TARGETS: MappingProxyType[str, str] = MappingProxyType(
    {
        "free_space": "free_space",
        "space": "free_space",
        "empty_space": "free_space",
        "free_area": "free_space",
        "empty_area": "free_space",
        "free_spot": "free_space",
        "empty_spot": "free_space",
        "free_surface": "free_space",
    }
)
"""Noun phrases that turn a search into ``scan { for: ... }``."""

SCAN_FOR: tuple[str, ...] = ("for",)
"""The word that introduces what a scan looks for."""

STOP_TASK_WORDS: frozenset[str] = frozenset({"task", "job", "query", "the"})
"""Words allowed between ``stop`` and the task number."""

STOP_ALL_WORDS: MappingProxyType[str, str] = MappingProxyType({"all": "all", "everything": "all"})
"""Words that stop every task: ``stop everything`` -> ``task: all``."""

IRREGULAR_PLURALS: MappingProxyType[str, str] = MappingProxyType(
    {
        "knives": "knife",
        "wives": "wife",
        "lives": "life",
        "leaves": "leaf",
        "loaves": "loaf",
        "halves": "half",
        "shelves": "shelf",
        "people": "person",
        "mice": "mouse",
        "children": "child",
        "feet": "foot",
        "teeth": "tooth",
        "geese": "goose",
        "men": "man",
        "women": "woman",
        "ones": "one",
        "cookies": "cookie",
        "movies": "movie",
        "pies": "pie",
        "ties": "tie",
        "tomatoes": "tomato",
        "potatoes": "potato",
        "mangoes": "mango",
    }
)
"""Plurals the suffix rules get wrong."""

PLURAL_ONLY: frozenset[str] = frozenset({"scissors", "tongs", "pliers", "tweezers", "jeans", "pants", "trousers"})
"""Nouns that are plural and have no singular."""

INVARIANT_WORDS: frozenset[str] = frozenset(
    {"lens", "gas", "news", "series", "species", "chassis", "this", "is", "was", "has"}
)
"""Words ending in ``s`` that are not plurals."""

PLURAL_SUFFIXES: tuple[tuple[str, str], ...] = (
    ("ies", "y"),
    ("sses", "ss"),
    ("shes", "sh"),
    ("ches", "ch"),
    ("xes", "x"),
    ("zzes", "zz"),
    ("ss", "ss"),
    ("us", "us"),
    ("is", "is"),
    ("s", ""),
)
"""Suffix rules ``plural -> singular``, first match wins (``ss`` -> unchanged)."""
