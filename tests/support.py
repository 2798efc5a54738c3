"""Small behaviours for tests of the runtime: scripted leaves and port-declaring annotators."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence

import numpy as np
import py_trees
from py_trees.common import Status

from robokudo.core.annotator import Annotator
from robokudo.core.threaded import ThreadedAnnotator
from robokudo.core.types import Annotation, CasType, ObjectHypothesis, Plane


class Scripted(py_trees.behaviour.Behaviour):
    """Returns the scripted statuses one per update; the last one repeats. Records lifecycle calls."""

    def __init__(self, name: str, script: Sequence[Status]) -> None:
        super().__init__(name=name)
        self.script = list(script)
        self.updates = 0
        self.initialised = 0
        self.terminated: list[Status] = []

    def initialise(self) -> None:
        self.initialised += 1

    def update(self) -> Status:
        status = self.script[min(self.updates, len(self.script) - 1)]
        self.updates += 1
        return status

    def terminate(self, new_status: Status) -> None:
        self.terminated.append(new_status)


def annotator_class(
    name: str,
    inputs: Sequence[type[CasType]] = (),
    outputs: Sequence[type[CasType]] = (),
    work: Callable[[Annotator], None] | None = None,
) -> type[Annotator]:
    """An Annotator subclass with these ports whose analyse() calls ``work`` (default: write one of each output)."""

    def analyse(self: Annotator) -> None:
        if work is not None:
            work(self)
            return
        for output in self.outputs:
            self.write(make_instance(output))

    return type(name, (Annotator,), {"inputs": tuple(inputs), "outputs": tuple(outputs), "analyse": analyse})


def make_instance(cas_type: type[CasType]) -> CasType:
    """A small valid instance of a CAS type for tests."""
    if cas_type is ObjectHypothesis:
        return ObjectHypothesis(point_indices=np.arange(3), mask=np.zeros((2, 2), bool), roi=(0, 0, 1, 1))
    if cas_type is Plane:
        return Plane(model=np.array([0.0, 0.0, 1.0, -1.0]), inlier_indices=np.arange(3))
    raise TypeError(f"no test instance for {cas_type.__name__}")


class Marker(Annotation):
    """A test-only annotation type (subclass of Annotation) used as a token in data-flow tests."""


def marker_type(name: str) -> type[Annotation]:
    """A fresh Annotation subtype, for data-flow tests."""
    return type(name, (Marker,), {})


class GatedWork(ThreadedAnnotator):
    """A threaded annotator that works until released (or cancelled), then writes a Plane."""

    outputs = (Plane,)

    def __init__(self, name: str = "gated", timeout: float = 10.0) -> None:
        super().__init__(name=name, timeout=timeout)
        self.release = threading.Event()
        self.started = threading.Event()
        self.finished = threading.Event()

    def analyse(self) -> None:
        self.started.set()
        try:
            while not self.release.wait(0.005):
                if self.cancelled:
                    return
            self.write(make_instance(Plane))
        finally:
            self.finished.set()
