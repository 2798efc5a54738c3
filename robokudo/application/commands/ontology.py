"""``robokudo ontology``: show terms, check the ontology, edit the user layer, its history, export and import.

Edits (``add-object``, ``remove-object``, ``synonym``, ``import``, ``undo``) go through
:class:`~reasoning.knowledge.editing.OntologyEditor`: locked, validated, written atomically and recorded in the
history ``log`` lists. A rejected edit or an unknown name exits with status 2 and a message on stderr; a failed
``check`` exits with 1.

``remove-object NAME`` also updates the belief store (``--store``, else ``$ROBOKUDO_BELIEF_STORE``, else the
user data dir; a store that does not exist is left alone): after the class is removed, the stored beliefs of
that class are reclassified as its parent class, keeping their other class alternatives
(:mod:`robokudo.application.reclassify`). An unusable store is reported before anything is removed.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict
from pathlib import Path

from reasoning.beliefs.store import BeliefStore, BeliefStoreError
from reasoning.errors import EditRejectedError, OntologyError, TermError
from reasoning.knowledge.editing import CheckReport, EditResult, OntologyEditor
from reasoning.knowledge.exchange import FORMATS, export_ontology
from reasoning.knowledge.history import HistoryEntry
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import AnnotatorSpec, Resolved
from reasoning.knowledge.sources import USER_ONTOLOGY_ENV
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.reclassify import remove_object_class
from robokudo.core.regions import RegionBox

HELP = "show, check, edit, undo, export and import the ontology"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``ontology`` options and its actions (add-object, show, check, remove-object)."""
    _common_options(parser, suppress=False)
    actions = parser.add_subparsers(dest="ontology_action", required=True, metavar="ACTION")

    add = actions.add_parser("add-object", help="add an object class to the user ontology")
    add.add_argument("name", help="the new class name, CamelCase (e.g. OatMilk)")
    add.add_argument(
        "--is-a",
        dest="is_a",
        action="append",
        required=True,
        metavar="PARENT",
        help="a parent class (repeat for several)",
    )
    add.add_argument(
        "--color",
        "--colour",
        dest="colors",
        action="extend",
        nargs="+",
        default=[],
        metavar="C",
        help="typical colour(s)",
    )
    add.add_argument("--shape", help="typical shape (box, cylinder, sphere, flat)")
    add.add_argument("--size", help="size class (small, medium, large)")
    add.add_argument("--material", help="material (ceramic, plastic, glass, ...)")
    see_through = add.add_mutually_exclusive_group()
    see_through.add_argument(
        "--transparent",
        dest="transparent",
        action="store_const",
        const=True,
        default=None,
        help="objects of the class are transparent",
    )
    see_through.add_argument(
        "--opaque",
        dest="transparent",
        action="store_const",
        const=False,
        help="objects of the class are not transparent",
    )
    add.add_argument("--stored-in", dest="stored_in", metavar="REGION", help="region class where it is kept")
    add.add_argument(
        "--text", dest="texts", action="extend", nargs="+", default=[], metavar="TEXT", help="text printed on it"
    )
    add.add_argument("--brand", help="brand printed on it")
    add.add_argument("--label", help="the label (default: the name's words, e.g. 'oat milk')")
    add.add_argument(
        "--synonym",
        dest="synonyms",
        action="append",
        default=[],
        metavar="WORD",
        help="another word for it (repeat for several)",
    )
    _common_options(add, suppress=True)

    show = actions.add_parser("show", help="show a class, region, annotator or value")
    show.add_argument("name", help="a name or a word (label, synonym, plural)")
    _common_options(show, suppress=True)

    check = actions.add_parser(
        "check", help="check the ontology with the annotator classes: loading, HermiT, CAS types against the runtime"
    )
    check.add_argument("--no-code", action="store_true", help="do not compare the CAS types with the runtime's classes")
    _common_options(check, suppress=True)

    remove = actions.add_parser(
        "remove-object",
        help="remove an object class from the user ontology; stored beliefs of it move to its parent class",
    )
    remove.add_argument("name")
    remove.add_argument(
        "--store",
        type=Path,
        default=None,
        help="belief store file (default: $ROBOKUDO_BELIEF_STORE or the user data dir)",
    )
    _common_options(remove, suppress=True)

    synonym = actions.add_parser("synonym", help="add or remove synonyms of a class, region or value")
    synonym.add_argument("name", help="the term (a name or a word)")
    synonym.add_argument("--add", action="append", default=[], metavar="WORD", help="a synonym to add (repeatable)")
    synonym.add_argument(
        "--remove", action="append", default=[], metavar="WORD", help="a synonym the user added to remove (repeatable)"
    )
    _common_options(synonym, suppress=True)

    log = actions.add_parser("log", help="list the edits of the user ontology (newest last)")
    log.add_argument("--triples", action="store_true", help="also print the triples each edit added and removed")
    log.add_argument("--json", action="store_true", help="print the history entries as JSON")
    _common_options(log, suppress=True)

    undo = actions.add_parser("undo", help="revert the last N edits of the user ontology (validated like any edit)")
    undo.add_argument("count", nargs="?", type=int, default=1, metavar="N", help="how many edits (default 1)")
    _common_options(undo, suppress=True)

    export = actions.add_parser("export", help="write the user layer (or everything) for Protégé, owlready2, ...")
    export.add_argument(
        "--format",
        choices=FORMATS,
        default="turtle",
        help="turtle, xml (RDF/XML) or owl (OWL/XML); default turtle",
    )
    export.add_argument("--merged", action="store_true", help="the shipped ontology, annotators and user layer as one")
    export.add_argument("--output", "-o", type=Path, default=None, metavar="FILE", help="write here (default stdout)")
    _common_options(export, suppress=True)

    imported = actions.add_parser(
        "import",
        help="bring classes (parents, labels, synonyms, colours, shapes, default locations) from an OWL file",
    )
    imported.add_argument("file", type=Path, help="Turtle, RDF/XML or OWL/XML")
    imported.add_argument(
        "--map",
        dest="mappings",
        action="append",
        default=[],
        metavar="NAMESPACE|IRI=NAME",
        help="take IRIs of another namespace as rk: names (NAMESPACE: every IRI starting with it becomes rk:<rest>; "
        "IRI=NAME: that IRI becomes rk:NAME); repeatable",
    )
    _common_options(imported, suppress=True)


def _common_options(parser: argparse.ArgumentParser, suppress: bool) -> None:
    """``--user-file`` and ``--no-reasoner``, accepted before or after the action (no default after it)."""
    parser.add_argument(
        "--user-file",
        type=Path,
        default=argparse.SUPPRESS if suppress else None,
        metavar="PATH",
        help=f"the user ontology file (default: ${USER_ONTOLOGY_ENV} or the user data directory)",
    )
    parser.add_argument(
        "--no-reasoner",
        action="store_true",
        default=argparse.SUPPRESS if suppress else False,
        help="skip HermiT; use the asserted hierarchy and disjointness only",
    )


def run(args: argparse.Namespace) -> int:
    """Carry out the chosen action; returns the exit status."""
    action = args.ontology_action
    try:
        kb = load_knowledge_base(args.user_file)
    except OntologyError as error:
        print(f"robokudo ontology: {error}", file=sys.stderr)
        return 1 if action == "check" else 2
    editor = OntologyEditor(kb, use_reasoner=not args.no_reasoner)
    try:
        if action == "show":
            print(describe(kb, args.name))
            return 0
        if action == "check":
            return _report(editor.check(code=not args.no_code))
        if action == "add-object":
            result = editor.add_object(
                args.name,
                args.is_a,
                colors=args.colors,
                shape=args.shape,
                size=args.size,
                material=args.material,
                transparent=args.transparent,
                stored_in=args.stored_in,
                texts=args.texts,
                brand=args.brand,
                label=args.label,
                synonyms=args.synonyms,
            )
            _print_result(result)
            print(describe(kb, result.name))
            return 0
        if action == "remove-object":
            return _remove_object(kb, editor, args.name, args.store)
        if action == "synonym":
            _print_result(editor.change_synonyms(args.name, add=args.add, remove=args.remove))
            print(describe(kb, args.name))
            return 0
        if action == "log":
            _print_log(editor.log(), triples=args.triples, as_json=args.json)
            return 0
        if action == "undo":
            _print_result(editor.undo(args.count))
            return 0
        if action == "export":
            return _export(kb, args.format, args.merged, args.output)
        if action == "import":
            namespaces = [m for m in args.mappings if "=" not in m]
            names = dict(m.rsplit("=", 1) for m in args.mappings if "=" in m)
            _print_result(editor.import_file(args.file, namespaces, names))
            return 0
    except (EditRejectedError, TermError, BeliefStoreError) as error:
        print(f"robokudo ontology {action}: {error}", file=sys.stderr)
        return 2
    raise ValueError(f"unknown ontology action {action!r}")


def _remove_object(kb: KnowledgeBase, editor: OntologyEditor, name: str, store_path: Path | None) -> int:
    """Remove the class, then move the stored beliefs of it to its parent class."""
    path = (store_path or BeliefStore.default_path()).expanduser()
    store = BeliefStore(path) if path.exists() else None  # an unusable store fails here, before the removal
    try:
        result, parent, moved = remove_object_class(kb, editor, name, store)
        _print_result(result)
        if moved:
            target = f"as {parent}" if parent else "with no class"
            print(f"reclassified {len(moved)} stored belief(s) of {result.name} {target} ({path})")
    finally:
        if store is not None:
            store.close()
    return 0


def _print_result(result: EditResult) -> None:
    done = {
        "add-object": f"added {result.name}",
        "remove-object": f"removed {result.name}",
        "synonym": f"changed the synonyms of {result.name}",
        "import": f"imported {result.name}",
        "undo": "undid " + ", ".join(f"edit {e.number} ({e.summary})" for e in result.undone),
    }[result.action]
    print(f"{done} ({result.user_file}); edit {result.number}, checked by: {result.checked_by}")
    for warning in result.warnings:
        print(f"warning: {warning}", file=sys.stderr)


def _print_log(entries: list[HistoryEntry], triples: bool, as_json: bool) -> None:
    if as_json:
        print(json.dumps([asdict(e) for e in entries], indent=2, ensure_ascii=False))
        return
    if not entries:
        print("no edits recorded")
        return
    print(f"{'#':>4}  {'time (UTC)':20s}  {'user':12s}  {'edit':40s}  triples")
    for entry in entries:
        counts = f"+{len(entry.added)} -{len(entry.removed)}"
        print(f"{entry.number:>4}  {entry.time:20s}  {entry.user[:12]:12s}  {entry.summary[:40]:40s}  {counts}")
        if triples:
            for line in entry.added:
                print(f"        + {line}")
            for line in entry.removed:
                print(f"        - {line}")


def _export(kb: KnowledgeBase, fmt: str, merged: bool, output: Path | None) -> int:
    data = export_ontology(kb, fmt, merged)
    if output is None:
        sys.stdout.buffer.write(data)
        sys.stdout.flush()
    else:
        output.write_bytes(data)
        what = "the merged ontology" if merged else f"the user layer {kb.user_file}"
        print(f"wrote {what} to {output} ({fmt})", file=sys.stderr)
    return 0


def _report(report: CheckReport) -> int:
    print(f"reasoner: {report.reasoner}")
    for warning in report.warnings:
        print(f"warning: {warning}")
    for problem in report.problems:
        print(f"problem: {problem}")
    print("ontology OK" if report.ok else f"{len(report.problems)} problem(s)")
    return 0 if report.ok else 1


# ---------------------------------------------------------------------------------------- show


def describe(kb: KnowledgeBase, name: str) -> str:
    """A readable description of the term ``name`` names (annotator, class, region or value)."""
    if name in kb.index.annotators:
        return _describe_annotator(kb, kb.annotator(name))
    if name in kb.index.cas_types:
        return _describe_class(kb, name, "CAS type")
    found = kb.resolve_all(name)
    if not found:
        kb.resolve(name)  # raises UnknownTermError with suggestions
    first = kb.resolve(name)
    text = _describe(kb, first)
    others = [f"{r.kind.replace('_', ' ')} {r.name}" for r in found if r != first]
    return text + (f"\n  (the word also names: {', '.join(others)})" if others else "")


def _describe(kb: KnowledgeBase, term: Resolved) -> str:
    if term.kind == "region":
        return _describe_region(kb, kb.region(term.name))
    if term.kind == "class":
        return _describe_object(kb, term.name)
    text = _describe_class(kb, term.name, term.kind.replace("_", " "))
    if term.kind == "region_class":
        regions = ", ".join(r.name for r in kb.regions_of_class(term.name)) or "-"
        text += f"\n  {'regions':12s} {regions}"
    return text


def _header(kb: KnowledgeBase, name: str, kind: str) -> list[str]:
    where = kb.defined_in(name)
    lines = [f"{name}  ({kind}" + (f", defined in {where.name})" if where else ")")]
    lines.append(f"  {'label':12s} {kb.label(name)}")
    lines.append(f"  {'synonyms':12s} {', '.join(kb.synonyms(name)) or '-'}")
    return lines


def _describe_class(kb: KnowledgeBase, name: str, kind: str) -> str:
    lines = _header(kb, name, kind)
    lines.append(f"  {'is a':12s} {', '.join(kb.superclasses(name, direct=True)) or '-'}")
    lines.append(f"  {'subclasses':12s} {', '.join(kb.subclasses(name, direct=True)) or '-'}")
    return "\n".join(lines)


def _describe_object(kb: KnowledgeBase, name: str) -> str:
    profile = kb.object_profile(name)
    lines = _describe_class(kb, name, "object class").splitlines()
    lines.append(f"  {'ancestors':12s} {', '.join(kb.superclasses(name)) or '-'}")

    def value(field: str, shown: str) -> None:
        origin = profile.origin(field)
        note = f"   (from {origin})" if origin and origin != name else ""
        lines.append(f"  {field.replace('_', ' '):12s} {shown}{note}")

    value("colors", ", ".join(kb.label(c) for c in profile.colors) or "-")
    value("shape", kb.label(profile.shape) if profile.shape else "-")
    value("size_class", kb.label(profile.size_class) if profile.size_class else "-")
    value("material", kb.label(profile.material) if profile.material else "-")
    value("transparent", {True: "yes", False: "no", None: "-"}[profile.transparent])
    stored = "-"
    if profile.stored_in:
        regions = ", ".join(r.name for r in kb.regions_of_class(profile.stored_in))
        stored = profile.stored_in + (f" (regions: {regions})" if regions else "")
    value("stored_in", stored)
    value("texts", ", ".join(repr(t) for t in profile.texts) or "-")
    value("brand", profile.brand or "-")
    told_apart = "yes" if kb.variants_differ_by_text(name) else "no"
    lines.append(f"  {'by text':12s} {told_apart}   (only printed text tells it from a look-alike sibling)")
    return "\n".join(lines)


def _describe_region(kb: KnowledgeBase, box: RegionBox) -> str:
    lines = _header(kb, box.name, "region")
    lines.append(f"  {'class':12s} {box.region_class}")
    lines.append(f"  {'map':12s} {box.semantic_map or '-'}")
    lines.append(f"  {'frame':12s} {box.frame}")
    lines.append(f"  {'position':12s} {' '.join(f'{v:g}' for v in box.position)}")
    lines.append(f"  {'orientation':12s} {' '.join(f'{v:g}' for v in box.orientation)}  (x y z w)")
    lines.append(f"  {'size':12s} {' '.join(f'{v:g}' for v in box.size)}")
    return "\n".join(lines)


def _describe_annotator(kb: KnowledgeBase, spec: AnnotatorSpec) -> str:
    lines = _header(kb, spec.name, "annotator")

    def names(values: tuple[str, ...] | frozenset[str]) -> str:
        return ", ".join(sorted(values)) or "-"

    lines.append(f"  {'class':12s} {spec.implemented_by}")
    lines.append(f"  {'inputs':12s} {names(spec.inputs)}")
    lines.append(f"  {'optional':12s} {names(spec.optional_inputs)}")
    lines.append(f"  {'outputs':12s} {names(spec.outputs)}")
    for field, values in (
        ("colours", spec.colors),
        ("shapes", spec.shapes),
        ("sizes", spec.sizes),
        ("materials", spec.materials),
        ("classes", spec.classes),
    ):
        if values:
            lines.append(f"  {field:12s} {names(values)}")
    lines.append(f"  {'needs':12s} {names(spec.preconditions)}")
    lines.append(f"  {'cost':12s} {spec.cost_ms:g} ms")
    lines.append(f"  {'reliability':12s} {spec.reliability:g}")
    return "\n".join(lines)
