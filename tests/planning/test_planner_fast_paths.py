"""The planner's fast paths agree with the reference definitions they replace, on random inputs.

- provider exclusions computed once per plan == :meth:`KnowledgeBase.providers` asked per type;
- fixpoints over bit masks == the plain closure over the providers (what the sensors can lead to);
- look-alike classes from the index == a scan over all classes.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import Conditions
from reasoning.planning.planner import _Catalog
from robokudo.application.knowledge import load_knowledge_base

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(Path(tmp_path_factory.mktemp("kb")) / "user.ttl")


def conditions() -> st.SearchStrategy[Conditions]:
    return st.builds(Conditions, depth=st.booleans(), region=st.booleans(), model=st.booleans(),
                     transparent=st.booleans())  # fmt: skip


def object_classes(kb: KnowledgeBase) -> st.SearchStrategy[str | None]:
    return st.none() | st.sampled_from(kb.names_of_kind("class"))


def reference_closure(
    kb: KnowledgeBase, sensors: frozenset[str], forbidden: frozenset[str], object_class: str | None, given: Conditions
) -> frozenset[str]:
    """Types producible from ``sensors`` (with supertypes) without producing a ``forbidden`` one, by repeated
    passes over every CAS type and its providers as :meth:`KnowledgeBase.providers` lists them."""
    known = set(sensors)
    for name in sensors:
        known |= set(kb.superclasses(name))
    grew = True
    while grew:
        grew = False
        for type_name in kb.cas_types():
            if type_name in known or type_name in forbidden:
                continue
            for spec in kb.providers(type_name, None, object_class, given):
                if spec.inputs and type_name not in spec.inputs and known.issuperset(spec.inputs):
                    known.add(type_name)
                    grew = True
                    break
    return frozenset(known)


@SETTINGS
@given(data=st.data())
def test_exclusions_give_the_providers_of_every_type(kb: KnowledgeBase, data: st.DataObject) -> None:
    object_class = data.draw(object_classes(kb))
    given_conditions = data.draw(conditions())
    excluded, own_types_only = kb.provider_exclusions(object_class, given_conditions)
    assert not excluded & own_types_only
    for type_name in kb.cas_types():
        expected = kb.providers(type_name, None, object_class, given_conditions)
        fast = [
            s
            for s in kb.index.providers[type_name]
            if s.name not in excluded and (s.name not in own_types_only or type_name in s.outputs)
        ]
        assert fast == expected, type_name


@SETTINGS
@given(data=st.data())
def test_fixpoints_over_masks_match_the_plain_closure(kb: KnowledgeBase, data: st.DataObject) -> None:
    read = sorted({t for spec in kb.annotators() if not spec.inputs for t in spec.outputs})  # what readers supply
    sensors = frozenset(data.draw(st.lists(st.sampled_from(read), min_size=1, max_size=4)))
    object_class = data.draw(object_classes(kb))
    given_conditions = data.draw(conditions())
    catalog = _Catalog(kb, sensors, object_class, given_conditions)
    assert catalog.producible == reference_closure(kb, sensors, frozenset(), object_class, given_conditions)
    # forbid mostly types that would be produced, where forbidding changes something
    candidates = sorted(catalog.producible - catalog.sensors) or kb.cas_types()
    forbidden = frozenset(data.draw(st.lists(st.sampled_from(candidates), max_size=3)))
    mask = catalog.producible_without(forbidden)
    found = frozenset(t for t, bit in kb.index.type_bits.items() if bit & mask)
    assert found == reference_closure(kb, sensors, forbidden, object_class, given_conditions)


@SETTINGS
@given(data=st.data())
def test_look_alikes_are_the_classes_that_look_the_same(kb: KnowledgeBase, data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(kb.names_of_kind("class")))
    profile = kb.object_profile(name)
    look = (frozenset(profile.colors), profile.shape, profile.size_class)
    scanned = []
    for other in kb.names_of_kind("class"):
        seen = kb.object_profile(other)
        if (frozenset(seen.colors), seen.shape, seen.size_class) == look:
            scanned.append(other)
    assert list(kb.look_alikes(name)) == scanned
