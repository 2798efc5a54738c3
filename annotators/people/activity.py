"""What a person does, from the geometry of its body keypoints: pointing, standing or waving.

An arm raised well away from the body (its shoulder-to-wrist direction ``min_point_elevation`` or more from
straight down) and nearly straight points; a wrist above the shoulders by ``wave_height`` waves; otherwise the
person stands. The scores are smooth (logistic) in these angles and heights, so a half-raised arm scores in
between. Optionally an ONNX image-text model (:mod:`annotators.people.image_text`) scores the person's image crop
against one prompt per activity; its scores are averaged with the geometry's.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import ClassVar

import numpy as np

from annotators.cloud.plane import up_in_camera
from annotators.people.image_text import ImageTextModel, ImageTextModelError
from annotators.people.keypoints import angle, arms, body_down
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import Activity, BodyKeypoints, CameraInfo, CasType, ColorImage, PersonHypothesis

ACTIVITIES: tuple[str, ...] = ("pointing", "standing", "waving")
"""The activities recognised, in the order of the scores."""

PROMPTS: dict[str, str] = {
    "pointing": "a photo of a person pointing at something",
    "standing": "a photo of a person standing",
    "waving": "a photo of a person waving a hand",
}
"""The default prompt per activity for an image-text model."""


def _logistic(x: float) -> float:
    return 1.0 / (1.0 + math.exp(-x))


def activity_scores(
    keypoints: BodyKeypoints,
    up: np.ndarray | None,
    min_point_elevation: float = math.radians(35.0),
    wave_height: float = 0.10,
) -> tuple[dict[str, float], str]:
    """Scores (0..1) of pointing, standing and waving from 3-D keypoints and the arm that points or waves ("" when
    no arm has depth). ``up`` is the world's up in the camera frame (None: the body's own axis is used)."""
    down = body_down(keypoints, up)
    best_point, best_wave, arm = 0.0, 0.0, ""
    for candidate in arms(keypoints) if down is not None else []:
        raised = -float(np.dot(candidate.wrist - candidate.shoulder, down))  # height of the wrist over the shoulder
        wave = _logistic((raised - wave_height) / 0.03)
        elevation = angle(candidate.reach, down)  # type: ignore[arg-type]
        straight = _logistic((candidate.straightness - 0.85) / 0.03)
        pointing = _logistic((elevation - min_point_elevation) / math.radians(5.0)) * straight * (1.0 - wave)
        if max(pointing, wave) > max(best_point, best_wave):
            arm = candidate.side
        best_point, best_wave = max(best_point, pointing), max(best_wave, wave)
    standing = (1.0 - best_point) * (1.0 - best_wave)
    return {"pointing": best_point, "standing": standing, "waving": best_wave}, arm


class ActivityRecognizer(Annotator):
    """Recognises what each person does (pointing, standing, waving) from its body keypoints' geometry, optionally
    together with an ONNX image-text model."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PersonHypothesis, BodyKeypoints)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo, ColorImage)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Activity,)
    capability: ClassVar[Capability] = Capability(
        label="activity recognizer",
        synonyms=("gesture recognizer", "action recognizer"),
        cost_ms=1.0,
        reliability=0.8,
    )

    def __init__(
        self,
        model_path: str | Path | None = None,
        prompts: dict[str, str] | None = None,
        min_point_elevation_degrees: float = 35.0,
        wave_height: float = 0.10,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.model_path = Path(model_path) if model_path is not None else None
        self.prompts = dict(prompts or PROMPTS)
        unknown = set(self.prompts) - set(ACTIVITIES)
        if unknown:
            raise ValueError(f"prompts for unknown activities {sorted(unknown)}; known: {', '.join(ACTIVITIES)}")
        self.min_point_elevation = math.radians(min_point_elevation_degrees)
        self.wave_height = wave_height

    def _model(self) -> ImageTextModel | None:
        if self.model_path is None:
            return None
        path = self.model_path
        return self.resources.get(("image-text", str(path)), lambda: ImageTextModel.load(path))

    def analyse(self) -> None:
        """Attach an Activity to every person with body keypoints."""
        up = up_in_camera(self.optional_view(CameraInfo))
        try:
            model = self._model()
        except ImageTextModelError as error:
            self.fail(str(error))
        image = self.optional_view(ColorImage) if model is not None else None
        recognised = 0
        for person in self.annotations(PersonHypothesis):
            keypoints = self.attached(person, BodyKeypoints)
            if not keypoints:
                continue
            scores, arm = activity_scores(keypoints[0], up, self.min_point_elevation, self.wave_height)
            if model is not None and image is not None:
                x0, y0, x1, y1 = person.roi
                asked = [a for a in ACTIVITIES if a in self.prompts]
                seen = model.scores(image.image[y0:y1, x0:x1], [self.prompts[a] for a in asked])
                for activity, score in zip(asked, seen, strict=True):
                    scores[activity] = (scores[activity] + score) / 2
            best = max(ACTIVITIES, key=lambda a: scores[a])
            self.attach(
                person,
                Activity(
                    activity=best,
                    scores=tuple((a, round(scores[a], 4)) for a in ACTIVITIES),
                    arm=arm if best != "standing" else "",
                    confidence=scores[best],
                ),
            )
            recognised += 1
        if not recognised:
            self.fail("no person with body keypoints to recognise an activity of")
