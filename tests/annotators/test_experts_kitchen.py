"""Every object expert on the built-in kitchen scene, against its ground truth: colour, shape, size class and
metric size, pose within 2 cm / 10°, and the knowledge classifier naming the objects from ontology profiles."""

from __future__ import annotations

import numpy as np
import pytest
from py_trees.common import Status

from annotators.classification.knowledge_classifier import KnowledgeClassifier
from annotators.cloud.form import FormAnnotator
from annotators.cloud.normals import NormalEstimator
from annotators.cloud.shape import ShapeAnnotator
from annotators.cloud.size import SizeAnnotator
from annotators.image.histogram import ColorHistogramAnnotator
from annotators.readers.frame_readers import KitchenSceneReader
from annotators.simulation.kitchen_scene import RenderedScene, SceneObject
from annotators.text.reader import TextReader
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.query_planner import class_profiles
from robokudo.core.engine import Engine
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import Classification, ColorHistogram, ObjectHypothesis, Pose, SemanticColor, Shape, Size, Text
from trees.tabletop import create_pipeline

CLASSES = ("Milk", "LactoseFreeMilk", "WholeMilk", "CerealBox", "Cup", "Glass", "Bowl", "Mug", "CrackerBox")


def profiles(kb: KnowledgeBase) -> list[dict[str, object]]:
    """The planner's plain-data profiles (colour, shape, size, texts and form) of some candidate classes."""
    return [profile for profile in class_profiles(kb) if profile["class"] in CLASSES]


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return KnowledgeBase.load(tmp_path_factory.mktemp("kb") / "user.ttl")


def run_view(view: str, kb: KnowledgeBase) -> tuple[Pipeline, RenderedScene]:
    reader = KitchenSceneReader(view=view)
    root = create_pipeline(reader)
    describe = ThresholdParallel(
        "measure", [NormalEstimator(), SizeAnnotator(), ColorHistogramAnnotator()], n_success=2
    )
    root.add_child(describe)
    root.add_child(ShapeAnnotator())
    root.add_child(FormAnnotator())
    root.add_child(TextReader())
    root.add_child(KnowledgeClassifier(profiles(kb)))
    status = Engine(root, hz=200.0).run(ticks=4000, until=lambda s: s is not Status.RUNNING)
    assert status is Status.SUCCESS, [(n.name, n.feedback_message) for n in root.iterate()]
    assert reader.last_scene is not None
    return root, reader.last_scene


@pytest.fixture(scope="module")
def views(kb: KnowledgeBase) -> dict[str, tuple[Pipeline, RenderedScene]]:
    return {view: run_view(view, kb) for view in ("table", "fridge")}


def objects_and_hypotheses(root: Pipeline, scene: RenderedScene) -> list[tuple[SceneObject, ObjectHypothesis]]:
    """Each hypothesis with the ground-truth object most of its pixels show (one hypothesis per object)."""
    pairs = []
    for hypothesis in root.cas.annotations(ObjectHypothesis):
        ids = scene.object_ids.reshape(-1)[hypothesis.point_indices]
        object_id = int(np.bincount(ids).argmax())
        pairs.append((next(o for o in scene.objects if o.object_id == object_id), hypothesis))
    assert len({o.name for o, _ in pairs}) == len(pairs)
    return pairs


@pytest.mark.parametrize("view", ["table", "fridge"])
def test_colour_shape_and_size_match_the_ground_truth(views, view: str) -> None:
    root, scene = views[view]
    pairs = objects_and_hypotheses(root, scene)
    assert {o.name for o, _ in pairs} == ({"cereal_box", "red_cup", "bowl"} if view == "table" else {"milk"})
    for obj, hypothesis in pairs:
        assert hypothesis.first(SemanticColor).color == obj.color, obj.name
        shape = hypothesis.first(Shape)
        assert shape.shape == obj.shape and shape.confidence > 0.3, (obj.name, shape)
        size = hypothesis.first(Size)
        assert size.size_class == obj.size_class, (obj.name, size)
        truth = sorted(obj.size, reverse=True)
        assert np.allclose(size.dimensions, truth, atol=0.02), (obj.name, size.dimensions, truth)
        histogram = hypothesis.first(ColorHistogram)
        assert histogram is not None and histogram.histogram.sum() == pytest.approx(1.0)


@pytest.mark.parametrize("view", ["table", "fridge"])
def test_poses_are_within_2_cm_and_10_degrees(views, view: str) -> None:
    root, scene = views[view]
    for obj, hypothesis in objects_and_hypotheses(root, scene):
        pose = hypothesis.first(Pose)
        assert pose.frame == "world"
        assert np.linalg.norm(pose.position - obj.position) < 0.02, obj.name
        rotation, truth = pose.matrix()[:3, :3], obj.pose[:3, :3]
        assert np.degrees(np.arccos(np.clip(rotation[:, 2] @ truth[:, 2], -1, 1))) < 10, obj.name  # upright
        if obj.shape == "box":  # yaw matters up to the box's symmetry (90°)
            yaw = np.degrees(np.arctan2(rotation[1, 0], rotation[0, 0]) - np.arctan2(truth[1, 0], truth[0, 0]))
            assert min(yaw % 90, 90 - yaw % 90) < 10, (obj.name, yaw)


def test_the_knowledge_classifier_names_every_object(views) -> None:
    # a cup and a glass have the same typical properties but for the glass being transparent, which no cue sees, so
    # the red cup is named by the class above both, a container (Glass is among the candidates: without it the cup's
    # only rivals would be ruled out by its form, and it would be named a cup with the whole of its score as its
    # lead); the milk's printed "lactose free" picks the most specific variant
    expected = {"cereal_box": "CerealBox", "red_cup": "Container", "bowl": "Bowl", "milk": "LactoseFreeMilk"}
    for root, scene in views.values():
        for obj, hypothesis in objects_and_hypotheses(root, scene):
            found = hypothesis.first(Classification)
            assert (found.class_name if found else None) == expected[obj.name], (obj.name, found)


def test_the_text_on_the_milk_carton_is_read_inside_its_box(views) -> None:
    root, scene = views["fridge"]
    ((_, hypothesis),) = objects_and_hypotheses(root, scene)
    texts = hypothesis.find(Text)
    assert len(texts) == 1
    words = texts[0].text.lower().split()
    assert words[:3] == ["milk", "lactose", "free"], texts[0].text
    x0, y0, x1, y1 = texts[0].box
    rx0, ry0, rx1, ry1 = hypothesis.roi
    assert rx0 - 8 <= x0 < x1 <= rx1 + 8 and ry0 - 8 <= y0 < y1 <= ry1 + 8
    assert 0.6 <= texts[0].confidence <= 1.0
    table, table_scene = views["table"]
    assert all(not h.find(Text) for _, h in objects_and_hypotheses(table, table_scene))  # nothing printed there
