"""Annotator: a behaviour-tree leaf that reads and writes its Pipeline's CAS through declared ports.

An expert subclasses :class:`Annotator`, declares ``inputs`` and ``outputs`` (CAS types) and its
:class:`~robokudo.core.capability.Capability` (label, value domains, preconditions, cost, reliability), and
implements :meth:`Annotator.analyse`. The class is the only declaration of an expert: the knowledge base reads
these ClassVars when it loads, so the planner knows the expert without any ontology file being edited.

The framework's :meth:`Annotator.update` finds the CAS (the nearest Pipeline above), runs ``analyse`` and
commits its writes only when it succeeds, so a failing expert leaves the CAS as it was. ``analyse`` fails by
calling :meth:`Annotator.fail`; any other exception also turns into FAILURE with the reason in
``feedback_message``, so nothing raises out of a tick. Port violations are programming errors and do raise
(:class:`PortError`).
"""

from __future__ import annotations

import logging
import threading
from time import perf_counter
from typing import ClassVar, NoReturn, TypeVar

import py_trees
from py_trees.common import Status

from robokudo.core.capability import Capability
from robokudo.core.cas import CAS, AddAnnotation, AttachAnnotation, CasWrite, SetView
from robokudo.core.explained import Explained
from robokudo.core.pipeline import Pipeline, StructureError, enclosing_pipeline, pipeline_named, tree_root
from robokudo.core.placement import Placement
from robokudo.core.resources import SharedResources
from robokudo.core.stats import RunStats
from robokudo.core.types import Annotation, CasType, ObjectHypothesis, View

V = TypeVar("V", bound=View)
A = TypeVar("A", bound=Annotation)

log = logging.getLogger(__name__)

# Status members looked up once: on Python 3.11 each ``Status.X`` costs ~100 ns, and these are on every tick's path.
_SUCCESS, _FAILURE, _INVALID = Status.SUCCESS, Status.FAILURE, Status.INVALID


class AnnotatorError(Exception):
    """Raised inside ``analyse`` to fail the annotator with a reason (bad input, nothing found, ...)."""


class PortError(Exception):
    """An annotator read or wrote a type it did not declare."""


class RunCancelledError(Exception):
    """The run this code belongs to was interrupted; its results are discarded."""


class _Run:
    """The state of one execution of ``analyse``: its pending writes and its cancel flag."""

    __slots__ = ("cancelled", "cas", "thread_ident", "writes")

    def __init__(self, cas: CAS, thread_ident: int | None) -> None:
        self.cas = cas
        self.thread_ident = thread_ident
        self.writes: list[CasWrite] = []
        self.cancelled = False  # set once by the tick thread; a plain flag is enough for the worker to poll


class Annotator(Explained, py_trees.behaviour.Behaviour):
    """A leaf expert with declared input and output CAS types and a declared capability.

    ``inputs`` must be in the CAS before it runs (the data-flow validator checks this); ``optional_inputs``
    are used when present; ``outputs`` are what it may write. ``capability`` says which values it can report,
    what it needs, what it costs and how reliable it is (the defaults: any value, no preconditions, 10 ms,
    reliability 0.5); the planner chooses experts from these declarations. ``placement`` says where it runs.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = ()
    outputs: ClassVar[tuple[type[CasType], ...]] = ()
    capability: ClassVar[Capability] = Capability()
    placement: ClassVar[Placement] = Placement()
    """Where it runs: locally (the default) or, with ``Placement(remote=True, ...)``, on a Ray actor whenever a tree
    holding it is placed (:func:`robokudo.core.remote.place_remote`)."""

    def __init__(self, name: str | None = None) -> None:
        super().__init__(name=name or type(self).__name__)
        self.reason = ""
        self.stats = RunStats()
        self.resources = SharedResources()
        """Where this annotator keeps its expensive objects (loaded models); a tree builder may hand every node
        one pool shared by many trees (:mod:`robokudo.core.resources`)."""
        self._run: _Run | None = None
        self._path_to_pipeline: tuple[py_trees.behaviour.Behaviour, ...] = ()  # parent, ..., enclosing Pipeline
        self._pipeline: Pipeline | None = None

    # ------------------------------------------------------------------ to be implemented by experts

    def analyse(self) -> None:
        """Do the work: read with :meth:`view`/:meth:`annotations`, write with :meth:`write`/:meth:`attach`."""
        raise NotImplementedError(f"{type(self).__name__} must implement analyse()")

    # ------------------------------------------------------------------ framework

    @property
    def cas(self) -> CAS:
        """The CAS of the nearest Pipeline above this annotator."""
        # Every run looks this up; re-walking the tree costs an ABC isinstance per ancestor, so the ancestors found
        # last time are kept and only checked to still be this node's chain of parents.
        node: py_trees.behaviour.Behaviour = self
        for ancestor in self._path_to_pipeline:
            if node.parent is not ancestor:
                break
            node = ancestor
        else:
            if self._pipeline is not None:
                return self._pipeline.cas
        pipeline = enclosing_pipeline(self)
        if pipeline is None:
            raise StructureError(f"annotator {self.name!r} is not inside a Pipeline, so it has no CAS")
        path = []
        ancestor = self.parent
        while ancestor is not pipeline:
            path.append(ancestor)
            ancestor = ancestor.parent
        path.append(pipeline)
        self._path_to_pipeline, self._pipeline = tuple(path), pipeline
        return pipeline.cas

    def cas_of(self, pipeline_name: str) -> CAS:
        """The CAS of another Pipeline in the same tree, by that Pipeline's name (StructureError if none)."""
        try:
            return pipeline_named(tree_root(self), pipeline_name).cas
        except KeyError as error:
            raise StructureError(f"annotator {self.name!r}: {error.args[0]}") from None

    def update(self) -> Status:
        """Run ``analyse`` on the CAS and commit its writes when it succeeds."""
        # the body of _execute, inlined: this is every annotator's tick path
        run = _Run(self.cas, None)
        self._run = run
        start = perf_counter()
        try:
            self.analyse()
        except Exception as error:
            status, message = self._outcome_of(error)
        else:
            status, message = _SUCCESS, ""
        self.stats.record(perf_counter() - start)
        if status is _SUCCESS and run.writes:
            run.cas.apply(run.writes)
        self.feedback_message = message
        return status

    def _execute(self, run: _Run) -> tuple[Status, str, float]:
        """Run ``analyse`` for ``run``; returns the status, a message and the duration in seconds."""
        self._run = run
        start = perf_counter()
        try:
            self.analyse()
        except Exception as error:
            status, message = self._outcome_of(error)
            return status, message, perf_counter() - start
        return _SUCCESS, "", perf_counter() - start

    def _outcome_of(self, error: Exception) -> tuple[Status, str]:
        """The status and message of a run that raised ``error``; port and structure errors (programming errors)
        and a missing ``analyse`` are raised again. Called only while ``error`` is being handled."""
        if isinstance(error, AnnotatorError):
            return _FAILURE, str(error)
        if isinstance(error, (PortError, StructureError, NotImplementedError)):
            raise error
        if isinstance(error, RunCancelledError):
            return _INVALID, "cancelled"
        log.debug("annotator %s crashed", self.name, exc_info=True)
        return _FAILURE, f"{type(error).__name__}: {error}"

    # ------------------------------------------------------------------ the expert's API

    def fail(self, reason: str) -> NoReturn:
        """Stop this run with FAILURE and ``reason``."""
        raise AnnotatorError(reason)

    @property
    def cancelled(self) -> bool:
        """True once this run was interrupted; long loops may poll it to stop early."""
        run = self._current_run()
        return run.cancelled

    def view(self, view_type: type[V]) -> V:
        """The CAS view of a declared input type; fails the run when it is missing."""
        found = self.optional_view(view_type)
        if found is None:
            self.fail(f"no {view_type.__name__} in the CAS")
        return found

    def optional_view(self, view_type: type[V]) -> V | None:
        """The CAS view of a declared input type, or None."""
        self._check_readable(view_type)
        return self._current_run().cas.view(view_type)

    def annotations(self, annotation_type: type[A]) -> list[A]:
        """Scene-level annotations of a declared input type (subtypes included)."""
        self._check_readable(annotation_type)
        return self._current_run().cas.annotations(annotation_type)

    def attached(self, hypothesis: ObjectHypothesis, annotation_type: type[A]) -> list[A]:
        """Annotations of a declared input type attached to ``hypothesis``."""
        self._check_readable(annotation_type)
        return hypothesis.find(annotation_type)

    def write(self, value: View | Annotation) -> None:
        """Set a view or add a scene-level annotation of a declared output type (committed on success)."""
        self._check_writable(type(value))
        write: CasWrite = SetView(value) if isinstance(value, View) else AddAnnotation(value)
        self._current_run().writes.append(write)

    def attach(self, hypothesis: ObjectHypothesis, annotation: Annotation) -> None:
        """Attach an annotation of a declared output type to a hypothesis (committed on success)."""
        self._check_writable(type(annotation))
        if not annotation.source:
            annotation.source = self.name
        self._current_run().writes.append(AttachAnnotation(hypothesis, annotation))

    # ------------------------------------------------------------------ port checks

    def _current_run(self) -> _Run:
        run = self._run
        if run is None:
            raise RuntimeError(f"annotator {self.name!r} used its CAS outside a run")
        if run.thread_ident is not None and run.thread_ident != threading.get_ident():
            raise RunCancelledError()
        if run.cancelled:
            raise RunCancelledError()
        return run

    def _check_readable(self, cas_type: type[CasType]) -> None:
        if not any(issubclass(cas_type, t) for t in self.inputs + self.optional_inputs + self.outputs):
            raise PortError(
                f"annotator {self.name!r} ({type(self).__name__}) read {cas_type.__name__}, which is not among "
                f"its declared inputs ({_names(self.inputs)})"
            )

    def _check_writable(self, cas_type: type[CasType]) -> None:
        if not any(issubclass(cas_type, t) for t in self.outputs):
            raise PortError(
                f"annotator {self.name!r} ({type(self).__name__}) wrote {cas_type.__name__}, which is not among "
                f"its declared outputs ({_names(self.outputs)})"
            )


class ConditionAnnotator(Annotator):
    """A condition leaf: SUCCESS when :meth:`check` holds, FAILURE otherwise; it writes nothing."""

    outputs: ClassVar[tuple[type[CasType], ...]] = ()

    def check(self) -> bool:
        """Evaluate the condition on the CAS."""
        raise NotImplementedError(f"{type(self).__name__} must implement check()")

    def analyse(self) -> None:
        """Turn the condition into a status."""
        if not self.check():
            self.fail(f"condition {self.name} does not hold")


def _names(types: tuple[type[CasType], ...]) -> str:
    return ", ".join(t.__name__ for t in types) or "none"
