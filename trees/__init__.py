"""Hand-authored Perception Pipeline Trees, found by module name.

A tree module defines ``create_tree(input_path: str | None = None, frame: int = 0) -> Behaviour`` and a
module docstring whose first line describes it. ``robokudo tree list`` shows them.
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from types import ModuleType

import py_trees

from robokudo.core.types import CameraIntrinsics


@dataclass(frozen=True)
class TreeSpec:
    """A tree module found in this package."""

    name: str
    summary: str
    module: ModuleType

    def create(
        self, input_path: str | None = None, frame: int = 0, intrinsics: CameraIntrinsics | None = None
    ) -> py_trees.behaviour.Behaviour:
        """Build a fresh instance of the tree (``intrinsics``: the camera of a point-cloud input, when given)."""
        if intrinsics is None:
            return self.module.create_tree(input_path=input_path, frame=frame)
        return self.module.create_tree(input_path=input_path, frame=frame, intrinsics=intrinsics)


def available_trees() -> dict[str, TreeSpec]:
    """Every tree module of this package, by name."""
    specs = {}
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        if hasattr(module, "create_tree"):
            summary = (module.__doc__ or "").strip().splitlines()[0] if module.__doc__ else ""
            specs[info.name] = TreeSpec(info.name, summary, module)
    return specs


def load_tree(name: str) -> TreeSpec:
    """The tree module called ``name``; raises KeyError listing the known trees."""
    specs = available_trees()
    if name not in specs:
        raise KeyError(f"no tree named {name!r}; known trees: {', '.join(sorted(specs)) or 'none'}")
    return specs[name]
