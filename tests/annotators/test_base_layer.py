"""A thin wide base under a narrower body (issue 15, item 6: the TUM teacup on its saucer): the form expert measures
the body above the base and notes the base; a mug on the table, a bowl, a can on a can and a box on a box have none.
Synthetic shapes in the upright support frame, as in tests/annotators/test_form.py."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from annotators.classification.knowledge_classifier import Cues, Profile, body_extent, score
from annotators.cloud.base_layer import find_base
from annotators.cloud.form import measure_form
from robokudo.core.types import FormFeatures
from tests.annotators.test_form import CENTRE, FRAME, handle, inner_far_wall, lid, side


def disc(radius: float, z: float, rng: np.random.Generator, n: int = 600, hole: float = 0.0) -> np.ndarray:
    """Points of a flat disc's top (a saucer, a plate) at height ``z``, without the part within ``hole`` of the
    centre (hidden under what stands on it) and without its far half's part behind a body of radius ``hole``."""
    r = radius * np.sqrt(rng.uniform(0.0, 1.0, 4 * n))
    a = rng.uniform(0.0, 2.0 * np.pi, 4 * n)
    xy = np.column_stack([r * np.cos(a), r * np.sin(a)])
    hidden = (r < hole) | ((xy[:, 1] > 0.0) & (np.abs(xy[:, 0]) < hole))
    xy = xy[~hidden][:n] + CENTRE
    return np.column_stack([xy, z + rng.normal(0.0, 0.002, xy.shape[0])])


def cup_on_saucer(rng: np.random.Generator) -> np.ndarray:
    """An open cup 4 cm in radius, 7 cm high, standing on a saucer 7.5 cm in radius, 1.5 cm thick."""
    cup = np.vstack([side(0.04, 0.07, rng), inner_far_wall(0.04, 0.07, rng)])
    cup[:, 2] += 0.015
    return np.vstack([cup, disc(0.075, 0.015, rng, hole=0.04)])


@pytest.mark.parametrize("seed", range(3))
def test_a_cup_on_its_saucer_is_measured_above_the_saucer(seed: int) -> None:
    rng = np.random.default_rng(seed)
    form = measure_form(cup_on_saucer(rng), FRAME)
    assert form is not None and form.base is not None
    assert form.base.base_width == pytest.approx(0.15, rel=0.1)
    assert form.base.body_width == pytest.approx(0.08, rel=0.1)
    assert form.height_to_width == pytest.approx(0.07 / 0.08, rel=0.15)  # with the saucer: 0.085 / 0.15
    assert form.open_top and not form.has_handle  # the saucer sticking out is no handle


def stacked(lower: np.ndarray, upper: np.ndarray, height: float) -> np.ndarray:
    """``upper`` standing on ``lower`` (``height`` high)."""
    upper = upper.copy()
    upper[:, 2] += height
    return np.vstack([lower, upper])


def box(width: float, depth: float, height: float, rng: np.random.Generator, n: int = 800) -> np.ndarray:
    """A closed box's near face and top, centred at CENTRE."""
    near_y = CENTRE[1] - depth / 2
    near = np.column_stack(
        [CENTRE[0] + rng.uniform(-width / 2, width / 2, n), np.full(n, near_y), rng.uniform(0.0, height, n)]
    )
    top = np.column_stack(
        [
            CENTRE[0] + rng.uniform(-width / 2, width / 2, n),
            near_y + rng.uniform(0.0, depth, n),
            np.full(n, height),
        ]
    )
    return np.vstack([near, top])


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize(
    "name",
    ["mug on the table", "cup on the table", "bowl", "can on a can", "box on a box", "narrow box on a wide box"],
)
def test_no_base_under_what_stands_on_the_table_or_on_a_tall_object(name: str, seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = {
        "mug on the table": lambda: np.vstack(
            [side(0.04, 0.1, rng), handle(0.04, 0.1, rng), inner_far_wall(0.04, 0.1, rng)]
        ),
        "cup on the table": lambda: np.vstack([side(0.04, 0.1, rng), inner_far_wall(0.04, 0.1, rng)]),
        "bowl": lambda: np.vstack([side(0.08, 0.06, rng), inner_far_wall(0.08, 0.06, rng)]),
        "can on a can": lambda: stacked(
            np.vstack([side(0.04, 0.1, rng), lid(0.04, 0.1, rng)]),
            np.vstack([side(0.035, 0.1, rng), lid(0.035, 0.1, rng)]),
            0.1,
        ),
        "box on a box": lambda: stacked(box(0.2, 0.1, 0.08, rng), box(0.2, 0.1, 0.06, rng), 0.08),
        "narrow box on a wide box": lambda: stacked(box(0.3, 0.2, 0.05, rng), box(0.1, 0.08, 0.15, rng), 0.05),
    }[name]()
    form = measure_form(points, FRAME)
    assert form is not None and form.base is None


def test_a_flat_layer_alone_has_no_body_on_it() -> None:
    rng = np.random.default_rng(0)
    plate = disc(0.12, 0.02, rng)
    assert find_base(plate, 0.0, float(np.quantile(plate[:, 2], 0.98))) is None


def test_a_cup_on_a_saucer_is_sized_by_the_cup() -> None:
    """The size expert measures the saucer (23 cm: medium); the classifier grades the size of the body on it."""
    on_saucer = FormFeatures(
        height_to_width=0.9,
        has_handle=False,
        handle_confidence=1.0,
        open_top=True,
        open_confidence=1.0,
        base_width=0.23,
        body_width=0.09,
    )
    alone = replace(on_saucer, base_width=None, body_width=None)
    assert body_extent(on_saucer) == pytest.approx(0.09)
    assert body_extent(alone) is None
    cup = Profile(class_name="Cup", size="small")
    sized = [
        score(cup, Cues(size=("medium", 1.0), extent=extent)).score
        for extent in (body_extent(on_saucer), body_extent(alone) or 0.23)
    ]
    assert sized[0] > sized[1]
