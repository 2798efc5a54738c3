"""The services a server offers over ``call_service``: plan, beliefs and ontology.

Each service declares the arguments it needs (checked when the request arrives: a missing or mistyped one gets a
``status`` error naming it) and a handler that runs on the goal manager's worker thread, which owns the answering
service; a handler's error becomes a failed ``service_response`` with the reason.

``/robokudo/ontology`` edits the user ontology as ``robokudo ontology`` does — the same locked, validated, recorded
transactions (:class:`~reasoning.knowledge.editing.OntologyEditor`) — and the running instance uses the result at
once. Arguments: ``action`` — ``show`` (``name``), ``add`` (``name``, ``is_a``; optional ``colors``, ``shape``,
``size``, ``material``, ``transparent``, ``stored_in``, ``texts``, ``brand``, ``label``, ``synonyms``), ``remove``
(``name``; the stored beliefs of the class move to its parent), ``synonym`` (``name``, ``add`` and/or ``remove``),
``undo`` (optional ``count``) and ``log``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass
from typing import Any

from queries import format_query, parse_query
from reasoning.knowledge.editing import EditResult, OntologyEditor
from robokudo.application.commands.ontology import describe
from robokudo.application.commands.plan import task_summary
from robokudo.application.reclassify import remove_object_class
from robokudo.application.server.protocol import BELIEFS_SERVICE, ONTOLOGY_SERVICE, PLAN_SERVICE
from robokudo.application.service import AnsweringService
from robokudo.core.render import tree_to_dict, unicode_tree

Arguments = Mapping[str, Any]


@dataclass(frozen=True)
class Service:
    """A service: the arguments it needs (name, type, what it holds) and its handler."""

    handler: Callable[[AnsweringService, Arguments], dict[str, Any]]
    needs: tuple[tuple[str, type, str], ...]

    def problem(self, name: str, arguments: object) -> str | None:
        """Why ``arguments`` cannot be passed to the service ``name`` (None when they can)."""
        if not isinstance(arguments, Mapping):
            return f"service {name!r} takes its arguments as an object ('args')"
        for argument, kind, what in self.needs:
            if not isinstance(arguments.get(argument), kind):
                return f"service {name!r} needs the argument {argument!r}: {what}"
        return None


def plan_service(service: AnsweringService, arguments: Arguments) -> dict[str, Any]:
    """``/robokudo/plan``: the interpretation, the synthesized tree and its explanation (nothing runs)."""
    query = parse_query(arguments["query"])
    query_plan = service.plan(query)
    tree = service.tree(query, query_plan)
    return {
        "query": format_query(query),
        "task": task_summary(query_plan),
        "tree": tree_to_dict(tree),
        "explanation": unicode_tree(tree, show_reasons=True),
    }


def beliefs_service(service: AnsweringService, arguments: Arguments) -> dict[str, Any]:
    """``/robokudo/beliefs``: the stored beliefs matching the query (nothing runs)."""
    return service.recall(arguments["query"]).to_dict()


def _text(arguments: Arguments, name: str, default: str | None = None) -> str | None:
    value = arguments.get(name, default)
    if value is not None and not isinstance(value, str):
        raise ValueError(f"argument {name!r} must be a string")
    return value


def _texts(arguments: Arguments, name: str) -> list[str]:
    value = arguments.get(name, [])
    values = [value] if isinstance(value, str) else value
    if not isinstance(values, list) or not all(isinstance(v, str) for v in values):
        raise ValueError(f"argument {name!r} must be a string or a list of strings")
    return values


def _name(arguments: Arguments) -> str:
    name = _text(arguments, "name")
    if not name:
        raise ValueError(f"ontology action {arguments['action']!r} needs the argument 'name'")
    return name


def _edited(service: AnsweringService, result: EditResult, **extra: Any) -> dict[str, Any]:
    try:
        described = describe(service.kb, result.name)
    except LookupError:  # the class is gone (removed, or its addition undone)
        described = ""
    return {
        "action": result.action,
        "name": result.name,
        "number": result.number,
        "checked_by": result.checked_by,
        "warnings": list(result.warnings),
        "description": described,
        **extra,
    }


def ontology_service(service: AnsweringService, arguments: Arguments) -> dict[str, Any]:
    """``/robokudo/ontology``: show, add, remove, synonym, undo, log (see the module)."""
    action = arguments["action"]
    service.kb.reload_if_changed()
    if action == "show":
        name = _name(arguments)
        return {"action": "show", "name": name, "description": describe(service.kb, name)}
    editor = OntologyEditor(service.kb)
    if action == "log":
        return {"action": "log", "entries": [asdict(entry) for entry in editor.log()]}
    if action == "add":
        transparent = arguments.get("transparent")
        if transparent is not None and not isinstance(transparent, bool):
            raise ValueError("argument 'transparent' must be true or false")
        result = editor.add_object(
            _name(arguments),
            _texts(arguments, "is_a"),
            colors=_texts(arguments, "colors"),
            shape=_text(arguments, "shape"),
            size=_text(arguments, "size"),
            material=_text(arguments, "material"),
            transparent=transparent,
            stored_in=_text(arguments, "stored_in"),
            texts=_texts(arguments, "texts"),
            brand=_text(arguments, "brand"),
            label=_text(arguments, "label"),
            synonyms=_texts(arguments, "synonyms"),
        )
        return _edited(service, result)
    if action == "remove":
        result, parent, moved = remove_object_class(service.kb, editor, _name(arguments), service.store)
        return _edited(service, result, reclassified=moved, reclassified_as=parent)
    if action == "synonym":
        result = editor.change_synonyms(
            _name(arguments), add=_texts(arguments, "add"), remove=_texts(arguments, "remove")
        )
        return _edited(service, result)
    if action == "undo":
        count = arguments.get("count", 1)
        if not isinstance(count, int) or isinstance(count, bool) or count < 1:
            raise ValueError("argument 'count' must be a whole number of edits, at least 1")
        result = editor.undo(count)
        return _edited(service, result, undone=[entry.number for entry in result.undone])
    raise ValueError(f"unknown ontology action {action!r}; actions: show, add, remove, synonym, undo, log")


SERVICES: Mapping[str, Service] = {
    PLAN_SERVICE: Service(plan_service, (("query", str, "the query text"),)),
    BELIEFS_SERVICE: Service(beliefs_service, (("query", str, "the query text"),)),
    ONTOLOGY_SERVICE: Service(ontology_service, (("action", str, "show, add, remove, synonym, undo or log"),)),
}
"""Every service the server offers, by name."""
