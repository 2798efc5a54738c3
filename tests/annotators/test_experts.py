"""The object experts on synthetic input: region and crop filters, normals, shape models, size classes,
colour histograms and the knowledge classifier's scoring."""

from __future__ import annotations

import numpy as np
import pytest
from py_trees.common import Status

from annotators.classification.knowledge_classifier import (
    UNKNOWN_CLASS,
    Cues,
    KnowledgeClassifier,
    Profile,
    decide,
    score,
)
from annotators.cloud.filters import CropBoxFilter, RegionFilter
from annotators.cloud.normals import grid_normals
from annotators.cloud.point_cloud import PointCloudGenerator
from annotators.cloud.shape import classify_shape
from annotators.cloud.size import SIZE_CLASS_THRESHOLDS, size_class_for
from annotators.image.histogram import ColorHistogramAnnotator, hue_saturation_histogram
from annotators.image.image_regions import ImageRegionSegmenter
from annotators.readers.frame_readers import KitchenSceneReader
from annotators.simulation import kitchen_scene
from robokudo.core.annotator import Annotator
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import (
    ANNOTATION_TYPES,
    VIEW_TYPES,
    Classification,
    ColorHistogram,
    ColorImage,
    ObjectHypothesis,
    PointCloud,
    SemanticColor,
    Shape,
    Size,
    Text,
)

# ----------------------------------------------------------------------------------------- filters


def run(*nodes: Annotator) -> Pipeline:
    pipeline = Pipeline("p", list(nodes))
    pipeline.tick_once()
    return pipeline


def region_filter(name: str) -> RegionFilter:
    box = next(r for r in kitchen_scene.kitchen_regions() if r.name == name)
    return RegionFilter(name, box.pose.reshape(-1).tolist(), box.size)


def test_region_filter_keeps_the_points_inside_the_map_box() -> None:
    reader = KitchenSceneReader(view="fridge")
    fridge = region_filter("fridge")
    pipeline = run(reader, PointCloudGenerator(), fridge)
    assert fridge.status is Status.SUCCESS, fridge.feedback_message
    cloud = pipeline.cas.view(PointCloud)
    scene = reader.last_scene
    kept_ids = scene.object_ids[cloud.mask]
    milk = scene.object("milk").object_id
    assert np.count_nonzero(kept_ids == milk) == np.count_nonzero(scene.object_ids == milk)  # all of the milk
    world = cloud.selected_points() @ scene.cam_to_world[:3, :3].T + scene.cam_to_world[:3, 3]
    box = next(r for r in kitchen_scene.kitchen_regions() if r.name == "fridge")
    assert all(box.contains(p) for p in world[:: max(1, len(world) // 300)])
    assert np.count_nonzero(cloud.mask) < 0.6 * np.count_nonzero(np.isfinite(cloud.points[..., 2]))


def test_region_filter_keeps_the_table_objects_and_fails_for_a_box_out_of_view() -> None:
    reader = KitchenSceneReader(view="table")
    table = region_filter("table")
    pipeline = run(reader, PointCloudGenerator(), table)
    assert table.status is Status.SUCCESS and table.name == "RegionFilter(table)"
    kept = set(np.unique(reader.last_scene.object_ids[pipeline.cas.view(PointCloud).mask]).tolist())
    assert {1, 2, 3} <= kept
    far = np.eye(4)
    far[:3, 3] = (50.0, 0.0, 0.0)
    away = RegionFilter("garden", far.ravel(), (1.0, 1.0, 1.0))
    run(KitchenSceneReader(view="table"), PointCloudGenerator(), away)
    assert away.status is Status.FAILURE and "inside region 'garden'" in away.feedback_message


@pytest.mark.parametrize(
    ("pose", "size"),
    [(np.eye(4).ravel()[:12], (1, 1, 1)), (np.eye(4).ravel(), (1, 0, 1)), (np.full(16, np.nan), (1, 1, 1))],
)
def test_region_filter_rejects_a_bad_box(pose: np.ndarray, size: tuple) -> None:
    with pytest.raises(ValueError):
        RegionFilter("table", pose, size)


def test_crop_box_keeps_the_points_inside_the_camera_frame_box() -> None:
    crop = CropBoxFilter(minimum=(-0.2, -1.0, 0.5), maximum=(0.2, 1.0, 2.0))
    pipeline = run(KitchenSceneReader(), PointCloudGenerator(), crop)
    points = pipeline.cas.view(PointCloud).selected_points()
    assert crop.status is Status.SUCCESS and points.shape[0] > 1000
    assert np.all((points[:, 0] >= -0.2) & (points[:, 0] <= 0.2) & (points[:, 2] >= 0.5) & (points[:, 2] <= 2.0))
    with pytest.raises(ValueError, match="below"):
        CropBoxFilter(minimum=(0, 0, 1), maximum=(1, 1, 1))


# ----------------------------------------------------------------------------------------- normals


def test_normals_of_a_tilted_plane_face_the_camera() -> None:
    v, u = np.mgrid[0:60, 0:80].astype(np.float32)
    rays = np.stack([(u - 40) / 500, (v - 30) / 500, np.ones_like(u)], axis=-1)
    normal = np.array([0.0, -0.6, -0.8])  # the plane n.p = -1 faces the camera
    depth = -1.0 / (rays @ normal)
    normals = grid_normals((rays * depth[..., None]).astype(np.float32), step=2, smoothing=3)
    inner = normals[5:-5, 5:-5].reshape(-1, 3)
    assert np.isfinite(inner).all()
    assert np.degrees(np.arccos(np.clip(inner @ normal, -1, 1))).max() < 1.0


def test_normals_are_unknown_across_depth_jumps_and_holes() -> None:
    v, u = np.mgrid[0:40, 0:40].astype(np.float32)
    depth = np.where(u < 20, 1.0, 1.5).astype(np.float32)
    depth[30:, 30:] = np.nan
    points = np.stack([(u - 20) / 50 * depth, (v - 20) / 50 * depth, depth], axis=-1).astype(np.float32)
    normals = grid_normals(points, step=2, smoothing=3)
    assert np.isnan(normals[10, 19:21]).all() and np.isnan(normals[31, 31]).all()
    assert np.allclose(normals[10, 8], (0, 0, -1), atol=1e-3)


# ----------------------------------------------------------------------------------------- shapes


def box_surface(rng: np.random.Generator, size: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Points and outward normals on the front (-y), right (+x) and top faces of an upright box on z = 0."""
    sx, sy, sz = size
    n = 400
    front = np.column_stack([rng.uniform(-sx / 2, sx / 2, n), np.full(n, -sy / 2), rng.uniform(0, sz, n)])
    right = np.column_stack([np.full(n, sx / 2), rng.uniform(-sy / 2, sy / 2, n), rng.uniform(0, sz, n)])
    top = np.column_stack([rng.uniform(-sx / 2, sx / 2, n), rng.uniform(-sy / 2, sy / 2, n), np.full(n, sz)])
    normals = np.repeat(np.array([[0, -1.0, 0], [1.0, 0, 0], [0, 0, 1.0]]), n, axis=0)
    return np.vstack([front, right, top]), normals


def cylinder_surface(rng: np.random.Generator, radius: float, height: float) -> tuple[np.ndarray, np.ndarray]:
    angle = rng.uniform(-np.pi, 0, 800)  # the half facing -y
    side = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0, height, 800)])
    side_normals = np.column_stack([np.cos(angle), np.sin(angle), np.zeros(800)])
    r, a = radius * np.sqrt(rng.uniform(0, 1, 300)), rng.uniform(0, 2 * np.pi, 300)
    top = np.column_stack([r * np.cos(a), r * np.sin(a), np.full(300, height)])
    return np.vstack([side, top]), np.vstack([side_normals, np.repeat([[0, 0, 1.0]], 300, axis=0)])


def sphere_surface(rng: np.random.Generator, radius: float) -> tuple[np.ndarray, np.ndarray]:
    direction = rng.normal(size=(1000, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    direction = direction[(direction[:, 1] < 0.2) & (direction[:, 2] > -0.3)]  # what a camera in front sees
    return direction * radius + (0, 0, radius), direction


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (lambda rng: box_surface(rng, (0.2, 0.07, 0.28)), "box"),
        (lambda rng: box_surface(rng, (0.07, 0.07, 0.2)), "box"),
        (lambda rng: cylinder_surface(rng, 0.04, 0.1), "cylinder"),
        (lambda rng: cylinder_surface(rng, 0.1, 0.08), "cylinder"),
        (lambda rng: sphere_surface(rng, 0.06), "sphere"),
        (lambda rng: box_surface(rng, (0.25, 0.2, 0.02)), "flat"),
    ],
)
def test_shape_models_tell_the_primitives_apart(make, expected: str) -> None:
    rng = np.random.default_rng(1)
    points, normals = make(rng)
    points = points + rng.normal(scale=0.001, size=points.shape)
    normals = normals + rng.normal(scale=0.05, size=normals.shape)
    fit = classify_shape(points, normals / np.linalg.norm(normals, axis=1, keepdims=True), on_plane=True)
    assert fit.shape == expected, fit
    assert 0.5 < fit.confidence <= 1.0


# ----------------------------------------------------------------------------------------- size classes


def test_size_classes_share_the_scene_thresholds() -> None:
    assert kitchen_scene.SIZE_CLASS_THRESHOLDS == SIZE_CLASS_THRESHOLDS == (0.12, 0.25)
    assert [size_class_for((v, 0.01, 0.01)) for v in (0.05, 0.119, 0.12, 0.249, 0.25, 1.0)] == [
        "small", "small", "medium", "medium", "large", "large",
    ]  # fmt: skip


# ----------------------------------------------------------------------------------------- histograms


def test_histogram_is_normalised_and_peaks_at_the_object_hue() -> None:
    red = np.tile(np.array([[220, 20, 20]], np.uint8), (500, 1))
    histogram = hue_saturation_histogram(red, (16, 4))
    assert histogram.shape == (16, 4) and histogram.sum() == pytest.approx(1.0)
    assert np.unravel_index(np.argmax(histogram), histogram.shape) == (0, 3)


def test_histogram_annotator_attaches_one_histogram_per_hypothesis() -> None:
    image = np.zeros((40, 60, 3), np.uint8)
    image[:, :30] = (20, 200, 30)
    image[:, 30:] = (30, 40, 220)
    hypotheses = []
    for x0 in (0, 30):
        mask = np.zeros((40, 60), bool)
        mask[5:35, x0 + 5 : x0 + 25] = True
        hypotheses.append(ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=(x0 + 5, 5, x0 + 25, 35)))
    annotator = ColorHistogramAnnotator()
    run(_Seed([ColorImage(image), *hypotheses]), annotator)
    assert annotator.status is Status.SUCCESS
    first, second = (h.first(ColorHistogram) for h in hypotheses)
    assert first.bins == (16, 4) and first.histogram.sum() == pytest.approx(1.0)
    assert np.argmax(first.histogram.sum(axis=1)) != np.argmax(second.histogram.sum(axis=1))


class _Seed(Annotator):
    outputs = VIEW_TYPES + ANNOTATION_TYPES

    def __init__(self, items: list) -> None:
        super().__init__(name="seed")
        self.items = items

    def analyse(self) -> None:
        for item in self.items:
            self.write(item)


# ----------------------------------------------------------------------------------------- classification

MILK = {"class": "Milk", "colors": ("White",), "shape": "Box", "size": "Medium", "texts": ("milk",),
        "ancestors": ("Milk", "Drink", "FoodOrDrink", "PhysicalObject")}  # fmt: skip
LACTOSE_FREE = {**MILK, "class": "LactoseFreeMilk", "texts": ("lactose free", "milk"),
                "ancestors": ("LactoseFreeMilk", "Milk", "Drink", "FoodOrDrink", "PhysicalObject")}  # fmt: skip
WHOLE = {**MILK, "class": "WholeMilk", "texts": ("whole", "milk"),
         "ancestors": ("WholeMilk", "Milk", "Drink", "FoodOrDrink", "PhysicalObject")}  # fmt: skip
CEREAL = {"class": "CerealBox", "colors": ("yellow",), "shape": "box", "size": "large", "texts": None}
CUP = {"class": "Cup", "shape": "cylinder", "size": "small", "ancestors": ("Cup", "Container", "PhysicalObject")}
PROFILES = [Profile.from_mapping(p) for p in (MILK, LACTOSE_FREE, WHOLE, CEREAL, CUP)]


def winner(evidence: Cues) -> str | None:
    decision = decide([score(p, evidence) for p in PROFILES])
    return None if decision.class_name == UNKNOWN_CLASS else decision.class_name


def test_text_picks_the_most_specific_matching_variant() -> None:
    white_box = Cues(color=("white", 0.9), shape=("box", 0.8), size=("medium", 1.0))
    assert winner(Cues(**{**white_box.__dict__, "text": "MILK lactose free"})) == "LactoseFreeMilk"
    assert winner(Cues(**{**white_box.__dict__, "text": "Whole MILK"})) == "WholeMilk"
    assert winner(Cues(**{**white_box.__dict__, "text": "MILK"})) == "Milk"
    # no text read: milk is named by its printed text, so a white box alone is not asserted to be milk; among these
    # profiles only drinks are white boxes, so it is named by the class above the milks
    assert winner(white_box) == "Drink"


def test_colour_shape_and_size_decide_without_text() -> None:
    assert winner(Cues(color=("yellow", 0.9), shape=("box", 0.7), size=("large", 1.0))) == "CerealBox"
    assert winner(Cues(color=("red", 0.9), shape=("cylinder", 0.8), size=("small", 1.0))) == "Cup"
    assert winner(Cues(color=("green", 0.9), shape=("sphere", 0.9), size=("large", 1.0))) is None


def test_uncertain_evidence_counts_less() -> None:
    milk = Profile.from_mapping(MILK)
    sure = score(milk, Cues(shape=("cylinder", 1.0))).score
    unsure = score(milk, Cues(shape=("cylinder", 0.2))).score
    assert sure == 0.0 and unsure == pytest.approx(0.4)


def test_the_classifier_attaches_classifications_and_fails_without_profiles() -> None:
    mask = np.zeros((10, 10), bool)
    mask[2:5, 2:5] = True
    hypothesis = ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=(2, 2, 5, 5))
    for annotation in (
        SemanticColor(color="white", confidence=0.9),
        Shape(shape="box", confidence=0.7),
        Size(dimensions=(0.2, 0.07, 0.07), size_class="medium"),
        Text(text="MILK lactose free"),
    ):
        hypothesis.annotations.append(annotation)
    classifier = KnowledgeClassifier([MILK, LACTOSE_FREE, CEREAL])
    run(_Seed([hypothesis]), classifier)
    assert classifier.status is Status.SUCCESS, classifier.feedback_message
    found = hypothesis.first(Classification)
    assert found is not None and found.class_name == "LactoseFreeMilk" and found.confidence > 0.9
    with pytest.raises(ValueError, match="class"):
        KnowledgeClassifier([{"colors": ("white",)}])


# ----------------------------------------------------------------------------- colour-only segmentation


def test_image_regions_find_the_table_objects_without_depth() -> None:
    reader = KitchenSceneReader()
    segmenter = ImageRegionSegmenter()
    pipeline = run(reader, segmenter)
    assert segmenter.status is Status.SUCCESS, segmenter.feedback_message
    hypotheses = pipeline.cas.annotations(ObjectHypothesis)
    scene = reader.last_scene
    for obj in scene.visible_objects():
        truth = scene.object_ids == obj.object_id
        best = max(np.count_nonzero(h.mask & truth) / np.count_nonzero(h.mask | truth) for h in hypotheses)
        assert best > 0.8, (obj.name, best)
    for hypothesis in hypotheses:
        rows, cols = np.nonzero(hypothesis.mask)
        assert hypothesis.roi == (cols.min(), rows.min(), cols.max() + 1, rows.max() + 1)
        assert np.array_equal(hypothesis.point_indices, np.flatnonzero(hypothesis.mask))


def test_the_queried_class_decides_between_near_equal_candidates() -> None:
    from annotators.classification.knowledge_classifier import choose_expected

    cola = Profile.from_mapping({"class": "Cola", "colors": ("red",), "shape": "cylinder", "size": "small"})
    cup = Profile.from_mapping({"class": "Cup", "shape": "cylinder", "size": "small", "ancestors": ("Container",)})
    bowl = Profile.from_mapping({"class": "Bowl", "shape": "sphere", "size": "medium"})
    evidence = Cues(color=("red", 0.3), shape=("cylinder", 0.8), size=("small", 1.0))
    matches = [score(p, evidence) for p in (cola, cup, bowl)]
    assert decide(matches).class_name == UNKNOWN_CLASS  # Cola and Cup are too close to call without a prior
    assert choose_expected(matches, "Cup", 0.6, 0.1).profile.class_name == "Cup"
    assert choose_expected(matches, "Container", 0.6, 0.1).profile.class_name == "Cup"
    assert choose_expected(matches, "Bowl", 0.6, 0.1) is None  # the prior never overrides clear evidence
