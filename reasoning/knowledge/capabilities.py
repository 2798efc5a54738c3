"""Agreement between the ontology's annotator declarations and the Python classes that implement them.

The ontology is the single source of truth for capabilities; :func:`check_implementations` verifies at
start-up (and in a test) that every declared annotator exists in the ``annotators`` package with exactly
the declared ports, and that every annotator class there is declared.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from collections.abc import Iterator
from types import ModuleType

from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import AnnotatorSpec
from reasoning.knowledge.vocabulary import ANNOTATORS_PACKAGE, IMPLEMENTATION_PATTERN
from robokudo.core.annotator import Annotator, ConditionAnnotator
from robokudo.core.types import ANNOTATION_TYPES, VIEW_TYPES


class ImplementationError(LookupError):
    """An annotator's declared implementation cannot be used."""


def load_implementation(spec: AnnotatorSpec) -> type[Annotator]:
    """Import the class an annotator is implemented by (only inside the ``annotators`` package)."""
    if IMPLEMENTATION_PATTERN.fullmatch(spec.implemented_by) is None:
        raise ImplementationError(
            f"{spec.name}: refusing to import {spec.implemented_by!r}, which is outside the "
            f"'{ANNOTATORS_PACKAGE}' package"
        )
    try:
        module = importlib.import_module(spec.module)
    except Exception as error:
        reason = f"{type(error).__name__}: {error}"
        raise ImplementationError(f"{spec.name}: cannot import {spec.module}: {reason}") from None
    cls = getattr(module, spec.class_name, None)
    if cls is None:
        raise ImplementationError(f"{spec.name}: {spec.module} has no class {spec.class_name}")
    if not (inspect.isclass(cls) and issubclass(cls, Annotator)):
        raise ImplementationError(f"{spec.name}: {spec.implemented_by} is not an Annotator subclass")
    return cls


def port_disagreements(spec: AnnotatorSpec, cls: type[Annotator]) -> list[str]:
    """How the class's ``inputs`` / ``optional_inputs`` / ``outputs`` differ from the ontology's ports."""
    problems = []
    ports = (("inputs", spec.inputs), ("optional_inputs", spec.optional_inputs), ("outputs", spec.outputs))
    for port, declared in ports:
        in_code = sorted(t.__name__ for t in getattr(cls, port))
        if in_code != sorted(declared):
            problems.append(
                f"{spec.implemented_by}: {port} disagree: code has [{', '.join(in_code)}], "
                f"ontology ({spec.name}) has [{', '.join(sorted(declared))}]"
            )
    return problems


def annotator_classes(package: str = ANNOTATORS_PACKAGE) -> Iterator[type[Annotator] | str]:
    """Every concrete Annotator subclass defined in ``package`` (an error message for a failing module)."""
    root = importlib.import_module(package)
    modules: list[ModuleType] = [root]
    for info in pkgutil.walk_packages(root.__path__, prefix=f"{package}."):
        try:
            modules.append(importlib.import_module(info.name))
        except Exception as error:
            yield f"{info.name}: cannot import: {type(error).__name__}: {error}"
    for module in modules:
        for _, cls in inspect.getmembers(module, inspect.isclass):
            if cls.__module__ == module.__name__ and issubclass(cls, Annotator) and _is_concrete(cls):
                yield cls


def _is_concrete(cls: type[Annotator]) -> bool:
    if cls.__name__.startswith("_") or inspect.isabstract(cls):
        return False
    if issubclass(cls, ConditionAnnotator):
        return cls.check is not ConditionAnnotator.check
    return cls.analyse is not Annotator.analyse


def check_implementations(kb: KnowledgeBase, package: str = ANNOTATORS_PACKAGE) -> list[str]:
    """Every disagreement between the ontology's annotators and the code (empty when they agree)."""
    problems: list[str] = []
    declared: dict[type[Annotator], str] = {}
    for spec in kb.annotators():
        try:
            cls = load_implementation(spec)
        except ImplementationError as error:
            problems.append(str(error))
            continue
        if cls in declared:
            problems.append(f"{spec.implemented_by} implements both {declared[cls]} and {spec.name}")
        declared[cls] = spec.name
        problems += port_disagreements(spec, cls)
    for found in annotator_classes(package):
        if isinstance(found, str):
            problems.append(found)
        elif found not in declared:
            problems.append(
                f"{found.__module__}.{found.__qualname__}: an Annotator in the '{package}' package that the "
                f"ontology does not declare (add it to ontology/annotators.ttl)"
            )
    return problems


def check_cas_types(kb: KnowledgeBase) -> list[str]:
    """How the ontology's CAS types differ from the runtime's (robokudo.core.types); empty when they agree."""
    problems = []
    for root, runtime in (("View", VIEW_TYPES), ("Annotation", ANNOTATION_TYPES)):
        in_code = {t.__name__ for t in runtime}
        in_ontology = set(kb.subclasses(root))
        for name in sorted(in_code - in_ontology):
            problems.append(f"runtime {root.lower()} type {name} is not a subclass of rk:{root} in the ontology")
        for name in sorted(in_ontology - in_code):
            problems.append(f"ontology {root.lower()} type {name} has no runtime class in robokudo.core.types")
    return problems
