"""The ontology's basic colours of a colour the namer cannot say (``rk:basicColor``: teal -> blue, green) agree with
the namer: every xkcd survey colour a person called by that colour's name (its label or a synonym as the head word:
"teal", "dark teal", "bright turquoise") is named by one of them, and each of them names some."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.image.color import COLOR_TERMS, name_colors
from annotators.image.color_prototypes import survey_colors, words
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.application.knowledge import load_knowledge_base


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


def uniform(hex_value: str) -> np.ndarray:
    """50 pixels of one sRGB colour."""
    return np.array([[int(hex_value[i : i + 2], 16) for i in (1, 3, 5)]] * 50, dtype=np.uint8)


def test_only_colours_the_namer_cannot_say_have_basic_colours(kb: KnowledgeBase) -> None:
    colours = kb.names_of_kind("color")
    with_basics = [c for c in colours if kb.basic_colors(c)]
    assert "Teal" in with_basics
    for colour in with_basics:
        assert kb.label(colour) not in COLOR_TERMS
        assert all(kb.label(basic) in COLOR_TERMS for basic in kb.basic_colors(colour))


@pytest.mark.parametrize("colour", ["Teal"])
def test_survey_colours_of_a_colour_are_named_by_its_basic_colours(kb: KnowledgeBase, colour: str) -> None:
    names = {kb.label(colour), *kb.synonyms(colour)}
    examples = [(name, hex_value) for name, hex_value in survey_colors() if words(name)[-1] in names]
    assert len(examples) >= 10, examples
    basics = {kb.label(basic) for basic in kb.basic_colors(colour)}
    said = {name: name_colors(uniform(hex_value))[0].name for name, hex_value in examples}
    assert set(said.values()) == basics, said
