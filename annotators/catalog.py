"""The annotator catalog: every expert and reader class this package defines, found by walking its modules.

The catalog is the one place that turns annotator names into classes: plans name annotators, and trees are
built only from classes in a catalog (this package's, plus classes a caller registers explicitly). Each class
declares its own capability (ports and ``capability``), so the catalog's classes are also what the application
loads into the knowledge base (``robokudo.application.knowledge.load_knowledge_base``).
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from collections.abc import Iterable, Iterator, Mapping
from types import ModuleType

from robokudo.core.annotator import Annotator, ConditionAnnotator

PACKAGE = "annotators"


class CatalogError(LookupError):
    """An annotator name that no class in the catalog carries, or two classes under one name."""


def _modules(package: str) -> Iterator[ModuleType]:
    root = importlib.import_module(package)
    yield root
    for info in pkgutil.walk_packages(root.__path__, prefix=f"{package}."):
        yield importlib.import_module(info.name)


def is_concrete(cls: type[Annotator]) -> bool:
    """True for an annotator class that can run: not private, not abstract, with its work implemented."""
    if cls.__name__.startswith("_") or inspect.isabstract(cls):
        return False
    if issubclass(cls, ConditionAnnotator):
        return cls.check is not ConditionAnnotator.check
    return cls.analyse is not Annotator.analyse


def discover_annotators(package: str = PACKAGE) -> list[type[Annotator]]:
    """Every concrete Annotator subclass defined in ``package`` and its subpackages, sorted by name."""
    found: list[type[Annotator]] = []
    for module in _modules(package):
        for _, cls in inspect.getmembers(module, inspect.isclass):
            if cls.__module__ == module.__name__ and issubclass(cls, Annotator) and is_concrete(cls):
                found.append(cls)
    return sorted(found, key=lambda cls: cls.__name__)


class AnnotatorCatalog(Mapping[str, type[Annotator]]):
    """Annotator classes by name (the class name, which is also the ontology individual's name)."""

    def __init__(self, classes: Iterable[type[Annotator]]) -> None:
        by_name: dict[str, type[Annotator]] = {}
        for cls in classes:
            other = by_name.setdefault(cls.__name__, cls)
            if other is not cls:
                raise CatalogError(f"two annotator classes are called {cls.__name__}: {_path(other)} and {_path(cls)}")
        self._by_name = by_name

    @classmethod
    def discover(cls, extra: Iterable[type[Annotator]] = ()) -> AnnotatorCatalog:
        """This package's annotators plus ``extra`` classes (e.g. a user's own experts)."""
        return cls([*discover_annotators(), *extra])

    def __getitem__(self, name: str) -> type[Annotator]:
        try:
            return self._by_name[name]
        except KeyError:
            known = ", ".join(sorted(self._by_name)) or "none"
            raise CatalogError(f"no annotator class called {name!r} in the catalog; known: {known}") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._by_name)

    def __len__(self) -> int:
        return len(self._by_name)


def _path(cls: type) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"
