"""Regions: the built-in kitchen map (same numbers as the scene), region classes, a user's map."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ontology import EXAMPLE_USER_MAP_FILE, ontology_dir
from reasoning.errors import OntologyError
from reasoning.knowledge.knowledge_base import KnowledgeBase
from tests.reasoning.helpers import write_ttl


def test_regions_of_class(kb: KnowledgeBase) -> None:
    assert [r.name for r in kb.regions_of_class("Fridge")] == ["fridge"]
    assert [r.name for r in kb.regions_of_class("Table")] == ["table"]
    assert [r.name for r in kb.regions_of_class("Region")] == ["fridge", "table"]
    assert kb.regions_of_class("Drawer") == []


def test_region_box(kb: KnowledgeBase) -> None:
    fridge = kb.region("fridge")
    assert fridge.frame == "world"
    assert fridge.semantic_map == "BuiltInKitchen"
    assert fridge.contains(fridge.position)
    assert not fridge.contains((0.0, 0.0, 0.0))
    assert fridge.pose.shape == (4, 4)
    np.testing.assert_allclose(fridge.pose[:3, 3], fridge.position)


def test_milk_is_searched_in_the_fridge_region(kb: KnowledgeBase) -> None:
    boxes = kb.regions_of_class(kb.default_location("milk") or "")
    assert [b.name for b in boxes] == ["fridge"]


def test_the_scene_reads_its_regions_from_the_knowledge_bases_map(kb: KnowledgeBase) -> None:
    from annotators.simulation.kitchen_scene import kitchen_regions

    assert kitchen_regions() == tuple(kb.regions())  # one map file, one region type: the same data


def test_the_rendered_objects_lie_in_the_regions_the_map_declares(kb: KnowledgeBase) -> None:
    from annotators.simulation.kitchen_scene import kitchen_objects

    stored_in = {"Milk": "fridge", "Cup": "table", "Bowl": "table", "CerealBox": "table"}
    for obj in kitchen_objects():
        assert obj.region == stored_in[obj.object_class], obj.name
        assert kb.region(obj.region).contains(obj.position), obj.name
        assert not any(r.contains(obj.position) for r in kb.regions() if r.name != obj.region), obj.name


def test_user_map_replaces_the_built_in_one(tmp_path: Path) -> None:
    kb = KnowledgeBase.load(tmp_path / "user.ttl", map_file=ontology_dir() / EXAMPLE_USER_MAP_FILE)
    assert "fridge" not in {r.name for r in kb.regions()}
    assert [r.name for r in kb.regions_of_class("Fridge")] == ["big_fridge", "fridge_door"]
    assert [r.name for r in kb.regions_of_class("Drawer")] == ["cutlery_drawer"]
    assert kb.region("cutlery drawer").region_class == "Drawer"
    shelf = kb.region("spice_shelf")
    assert shelf.frame == "map"
    np.testing.assert_allclose(shelf.pose[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-6)
    along_rotated_x = np.asarray(shelf.position) + np.array([0.0, 0.35, 0.0])
    assert shelf.contains(along_rotated_x)


def test_region_without_pose_is_rejected(tmp_path: Path) -> None:
    extra = write_ttl(tmp_path / "map.ttl", 'rk:pantry_1 a owl:NamedIndividual , rk:Pantry ; rk:frame "map" .\n')
    with pytest.raises(OntologyError, match="pantry_1"):
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra])


def test_scene_objects_use_ontology_terms(kb: KnowledgeBase) -> None:
    from annotators.simulation.kitchen_scene import kitchen_objects

    for obj in kitchen_objects():
        assert kb.kind(obj.object_class) == "class", obj.object_class
        assert kb.resolve(obj.color, kinds={"color"}).name in kb.names_of_kind("color")
        assert kb.resolve(obj.shape, kinds={"shape"}).kind == "shape"
        assert kb.resolve(obj.size_class, kinds={"size"}).kind == "size"
        if obj.region:
            assert kb.region(obj.region).name == obj.region
    milk = next(o for o in kitchen_objects() if o.object_class == "Milk")
    assert kb.region(milk.region).region_class == kb.default_location("Milk")
