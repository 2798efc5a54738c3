"""One answering service on the built-in kitchen, shared by test modules that put a person in it."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from annotators.image.human_pose import PoseModelError, load_pose_model
from robokudo.application.service import AnsweringService


def require_pose_model() -> None:
    """Skip the test when the human pose model cannot load."""
    try:
        load_pose_model()
    except PoseModelError as error:
        pytest.skip(str(error))


def kitchen_service_with_pose(tmp_path_factory: pytest.TempPathFactory, label: str) -> Iterator[AnsweringService]:
    """Yield a service with its own user ontology and belief store in a fresh folder named ``label``; skip the
    module when the pose model cannot load (tests that need it say so through this skip)."""
    require_pose_model()
    folder = tmp_path_factory.mktemp(label)
    with pytest.MonkeyPatch.context() as env:
        env.setenv("ROBOKUDO_USER_ONTOLOGY", str(folder / "user.ttl"))
        with AnsweringService.open(folder / "beliefs.sqlite") as opened:
            yield opened
