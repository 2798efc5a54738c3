"""The hand-labelled colour test set on real frames (tests/data/colors/real_colors.json, read from ../shared/data).

On the objects the issue's work was measured on (the first labelling round: its "tune" and "held_out" objects, 84),
at least 90% get as their dominant colour a name a person gave them and at least 90% are named exactly as labelled
(both colours of a two-coloured object, no unlisted second colour); the cases people complained about come out
right. The second round's 49 objects (labelled later; now split into "tune" and "fresh") are not yet at 90%: every
one the namer names as labelled today must stay so (a regression guard). Accuracy per split, with the
90% goal, is printed by bench/bench_color.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from annotators.image.color import name_colors
from annotators.image.color_surfaces import object_pixels
from annotators.image.white_balance import estimate_frame_light
from robokudo.core.types import ObjectHypothesis
from tests.annotators.color_set import (
    FIRST_ROUND,
    SHARED_DATA,
    SPLITS,
    ColorSample,
    is_named_as_labelled,
    load_frame,
    load_samples,
    sample_mask,
)
from tests.annotators.conftest import require_folder

pytestmark = pytest.mark.real_data

MIN_DOMINANT = 0.9
"""Share of objects whose dominant reported colour is one a person named."""

MIN_AS_LABELLED = 0.90
"""Share of objects named exactly as labelled (:func:`~tests.annotators.color_set.is_named_as_labelled`)."""

SECOND_ROUND_NAMED_AS_LABELLED = (
    "five_people#0:pale green polo shirt",
    "five_people#0:navy top",
    "five_people#0:white t-shirt",
    "five_people#0:dark navy t-shirt",
    "five_people#0:black trousers",
    "five_people#0:dark jeans",
    "five_people#0:grey denim shorts",
    "tum_rgbd_sample_open3d#0:wooden partition",
    "tum_rgbd_sample_open3d#0:white cabinet front",
    "learn5#0:toffee box",
    "learn6#0:lime tea box",
    "learn9#0:lime tea box",
    "learn14#0:white box with coloured edges",
    "learn15#0:white box with coloured edges",
    "learn16#0:red box",
    "learn17#0:yellow biscuit box",
    "learn20#0:yellow biscuit box",
    "learn22#0:white box",
    "learn22#0:red and white cereal box",
    "learn24#0:red and white cereal box",
    "learn28#0:narrow yellow box",
    "learn29#0:yellow biscuit box",
    "learn35#0:pale yellow tub",
    "learn35#0:cookie tin",
    "learn35#0:white bowl",
    "learn36#0:cookie tin",
    "learn36#0:pale yellow tub",
    "learn38#0:cookie tin",
    "learn38#0:pale yellow tub",
    "learn39#0:white cup",
    "learn39#0:white mug with a picture",
    "learn39#0:pale yellow tub",
    "learn40#0:cookie tin",
    "learn42#0:cookie tin",
    "learn42#0:white tin with red dots",
    "learn8#0:red and white cereal box",
    "learn25#0:orange muesli box",
    "learn27#0:red and cream cereal box",
    "learn31#0:crisps tube",
    "learn32#0:crisps tube",
    "five_people#0:light jeans",
    "five_people#0:faded jeans",
)
"""The second labelling round's objects the namer names as labelled today (42 of 49): none may be lost."""


def reported_names(sample: ColorSample) -> list[str]:
    """The names the namer reports for a labelled object (dominant first), as the annotator computes them."""
    frame = load_frame(sample.input, sample.frame)
    mask = sample_mask(sample, frame)
    ys, xs = np.nonzero(mask)
    roi = (int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1)
    hypothesis = ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=roi)
    pixels, edges = object_pixels(frame.color, hypothesis, 1000)
    return [color.name for color in name_colors(pixels, estimate_frame_light(frame.color), edges)]


@pytest.fixture(scope="module")
def results(shared_data: Path) -> dict[str, tuple[ColorSample, list[str]]]:
    samples = load_samples()
    for sample in samples:
        require_folder(SHARED_DATA / Path(sample.input).parts[0])
    return {sample.key: (sample, reported_names(sample)) for sample in samples}


def test_the_set_is_large_varied_and_split(results: dict[str, tuple[ColorSample, list[str]]]) -> None:
    samples = [sample for sample, _ in results.values()]
    assert len(samples) >= 40
    assert len({Path(s.input).parts[0] for s in samples}) >= 5
    assert len({s.colors[0] for s in samples}) >= 10
    assert {s.split for s in samples} == set(SPLITS)


def _first_round(results: dict[str, tuple[ColorSample, list[str]]]) -> dict[str, tuple[ColorSample, list[str]]]:
    return {key: value for key, value in results.items() if value[0].labelling_round == FIRST_ROUND}


def test_nine_in_ten_objects_get_the_colour_a_person_gives_them(
    results: dict[str, tuple[ColorSample, list[str]]],
) -> None:
    measured = _first_round(results)
    wrong = {
        key: (sample.colors + sample.alternatives, names)
        for key, (sample, names) in measured.items()
        if names[0] not in sample.colors + sample.alternatives
    }
    accuracy = 1.0 - len(wrong) / len(measured)
    assert accuracy >= MIN_DOMINANT, f"{accuracy:.0%} have a dominant colour a person gave; wrong: {wrong}"


def test_most_objects_are_named_exactly_as_labelled(results: dict[str, tuple[ColorSample, list[str]]]) -> None:
    measured = _first_round(results)
    wrong = {
        key: (sample.colors, names)
        for key, (sample, names) in measured.items()
        if not is_named_as_labelled(sample, names)
    }
    accuracy = 1.0 - len(wrong) / len(measured)
    assert accuracy >= MIN_AS_LABELLED, f"{accuracy:.0%} named as labelled; wrong: {wrong}"


def test_no_second_round_object_named_as_labelled_today_is_lost(
    results: dict[str, tuple[ColorSample, list[str]]],
) -> None:
    lost = {
        key: (results[key][0].colors, results[key][1])
        for key in SECOND_ROUND_NAMED_AS_LABELLED
        if not is_named_as_labelled(*results[key])
    }
    assert not lost, f"second-round objects no longer named as labelled: {lost}"


@pytest.mark.parametrize(
    ("key", "expected"),
    [
        ("uoc_tabletop_realsense#4:purple cup", ["purple"]),  # not pink
        ("uoc_tabletop_realsense#0:navy mug", ["blue"]),  # not black
        ("uoc_tabletop_realsense#1:navy mug", ["blue"]),
        ("uoc_tabletop_realsense#0:power drill", ["orange", "black"]),  # not red, and two-coloured
        ("learn34#0:cookie tin", ["brown"]),  # not red or orange
        ("pcl_grabber_sequences#0:cardboard box", ["brown"]),  # not yellow in a dark frame
        ("learn33#0:pale yellow tub", ["yellow"]),  # not white
        ("uoc_tabletop_realsense#0:black can", ["black"]),
        ("learn34#0:white bowl", ["white"]),  # not blue under the frame's cast
        ("tum_rgbd_sample_open3d#0:yellow chair seat", ["yellow"]),  # not orange in a dim room
    ],
)
def test_the_cases_people_complained_about(
    results: dict[str, tuple[ColorSample, list[str]]], key: str, expected: list[str]
) -> None:
    assert results[key][1] == expected


@pytest.mark.parametrize(
    "key",
    ["learn25#0:orange muesli box", "learn26#0:orange muesli box", "learn27#0:red and cream cereal box"],
)
def test_cream_and_yellow_boxes_with_a_white_print_are_not_brown_in_a_dim_frame(
    results: dict[str, tuple[ColorSample, list[str]]], key: str
) -> None:
    sample, names = results[key]
    assert "brown" not in names
    assert set(names) & set(sample.colors + sample.alternatives) - {"white", "red"}, names  # its cream or orange


def test_brown_things_stay_brown(results: dict[str, tuple[ColorSample, list[str]]]) -> None:
    # every split ("fresh2" is tuned on from the fourth round, colour11; its cookie tins are all brown now)
    browns = {key: names for key, (sample, names) in results.items() if sample.colors[0] == "brown"}
    assert len(browns) >= 10
    assert all(names[0] in ("brown", *results[key][0].alternatives) for key, names in browns.items()), browns


def test_an_olive_print_on_a_white_carton_is_not_brown(results: dict[str, tuple[ColorSample, list[str]]]) -> None:
    # the milk carton's dark olive print (hue about 106 degrees, greener than any brown people named) is green
    sample, names = results["milk_cartoon_all_small_clorox#0:milk carton"]
    assert "brown" not in names
    assert is_named_as_labelled(sample, names), names


def test_a_reddish_brown_tin_in_a_bright_frame_is_brown_not_pink(
    results: dict[str, tuple[ColorSample, list[str]]],
) -> None:
    # learn43's cookie tin on the light table: its lit side (L* 57, hue 40) is lighter than in the other views and
    # the survey's low-chroma pinks outvote the browns, but its hue is more orange than any pink people named
    sample, names = results["learn43#0:cookie tin"]
    assert "pink" not in names
    assert is_named_as_labelled(sample, names), names


@pytest.mark.parametrize("key", ["five_people#0:light jeans", "five_people#0:faded jeans"])
def test_jeans_whose_folds_are_in_shade_are_not_black(
    results: dict[str, tuple[ColorSample, list[str]]], key: str
) -> None:
    # pale denim in a dim room: the lit cloth is grey (its blue is within the white-balance allowance), its folds
    # darker; the folds are the cloth in shade, so the jeans are grey (a labelled name), not black
    assert results[key][1] == ["grey"]
