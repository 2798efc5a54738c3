"""Where the ontology comes from: the shipped files, a semantic map, extra files and the user file."""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import platformdirs
from rdflib import Graph
from rdflib.namespace import OWL, RDF, SKOS
from rdflib.plugins.stores.memory import SimpleMemory

from ontology import shipped_files
from reasoning.errors import OntologyError
from reasoning.knowledge.vocabulary import RK, is_rk, local_name

USER_ONTOLOGY_ENV = "ROBOKUDO_USER_ONTOLOGY"
"""Environment variable that overrides the default user ontology path."""


def default_user_file() -> Path:
    """The user ontology file: ``$ROBOKUDO_USER_ONTOLOGY`` or ``<user data dir>/robokudo/user.ttl``."""
    override = os.environ.get(USER_ONTOLOGY_ENV)
    if override:
        return Path(override).expanduser()
    return Path(platformdirs.user_data_dir("robokudo")) / "user.ttl"


@dataclass(frozen=True)
class Sources:
    """The read-only ontology files (in load order) and the user's file layered over them."""

    files: tuple[Path, ...]
    user_file: Path

    @classmethod
    def default(
        cls,
        user_file: Path | None = None,
        map_file: Path | None = None,
        extra_files: Sequence[Path] = (),
        files: Sequence[Path] | None = None,
    ) -> Sources:
        """Shipped files + map (or ``files`` instead) + ``extra_files``; the user file defaults as documented."""
        base = tuple(Path(f) for f in files) if files is not None else shipped_files(map_file)
        return cls(
            files=(*base, *(Path(f) for f in extra_files)),
            user_file=Path(user_file) if user_file is not None else default_user_file(),
        )


Stamp = tuple[int, int, int]
"""A file's change marker: (mtime in ns, size, inode); atomic replacement always gives a new inode."""


def file_stamp(path: Path) -> Stamp | None:
    """A cheap change marker of a file, or None when it does not exist."""
    try:
        stat = path.stat()
    except FileNotFoundError:
        return None
    return stat.st_mtime_ns, stat.st_size, stat.st_ino


def parse_turtle(path: Path, data: bytes | None = None) -> Graph:
    """Parse a Turtle file (or ``data`` in place of its content); OntologyError on any syntax error."""
    graph = Graph()
    try:
        if data is None:
            graph.parse(source=str(path), format="turtle")
        else:
            graph.parse(data=data, format="turtle", publicID=path.as_uri())
    except FileNotFoundError:
        raise OntologyError([f"{path}: no such file"]) from None
    except Exception as error:  # rdflib raises several unrelated types for syntax errors
        raise OntologyError([f"{path}: not valid Turtle: {error}"]) from None
    return graph


def merge_graphs(graphs: Iterable[Graph]) -> Graph:
    """One graph holding the triples of all ``graphs`` (their prefixes included).

    It lives in a context-free store: merging and indexing take half the time of rdflib's default store."""
    merged = Graph(store=SimpleMemory())
    merged.bind("rk", RK)
    merged.bind("owl", OWL)
    merged.bind("skos", SKOS)
    add = merged.add
    for graph in graphs:
        for triple in graph:
            add(triple)
    return merged


def defined_names(graphs: Mapping[Path, Graph]) -> dict[str, Path]:
    """Each ``rk:`` term given a type in one of the files -> the first file that does so."""
    defined: dict[str, Path] = {}
    for path, graph in graphs.items():
        for subject in graph.subjects(RDF.type, None):
            if is_rk(subject):
                defined.setdefault(local_name(subject), path)
    return defined
