"""Rendering of a Perception Pipeline Tree as unicode text, Graphviz dot and SVG."""

from __future__ import annotations

import shutil
import subprocess

import py_trees
from py_trees.common import Status

from robokudo.core.annotator import Annotator
from robokudo.core.explained import reason_of
from robokudo.core.loop import Loop
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.pipeline import Pipeline
from robokudo.core.slot import PerceiveThenTask, TaskSlot

_STATUS_MARK = {Status.SUCCESS: "✔", Status.FAILURE: "✘", Status.RUNNING: "…", Status.INVALID: " "}


def node_kind(node: py_trees.behaviour.Behaviour) -> str:
    """A short name of the node's role: Pipeline, Sequence, Fallback, Parallel, Slot, Annotator, Behaviour."""
    if isinstance(node, Pipeline):
        return "Pipeline"
    if isinstance(node, TaskSlot):
        return "Slot"
    if isinstance(node, ThresholdParallel | py_trees.composites.Parallel):
        return "Parallel"
    if isinstance(node, py_trees.composites.Selector):
        return "Fallback"
    if isinstance(node, py_trees.composites.Sequence | PerceiveThenTask):
        return "Sequence"
    if isinstance(node, Annotator):
        return "Annotator"
    if isinstance(node, Loop):
        return "Loop"
    if isinstance(node, py_trees.decorators.Decorator):
        return "Decorator"
    return "Behaviour"


def _label(node: py_trees.behaviour.Behaviour) -> str:
    kind = node_kind(node)
    if isinstance(node, Annotator):
        if type(node).__name__ != node.name:
            return f"{node.name} [{type(node).__name__}]"
        return node.name
    if isinstance(node, ThresholdParallel):
        return f"{kind} {node.name} (success > {node.n_success}, failure > {node.n_failure})"
    if isinstance(node, Loop):
        until = "until stopped" if node.runs is None else f"{node.runs} runs"
        return f"↻ {node.name} ({until})"
    return f"{kind} {node.name}"


def unicode_tree(
    root: py_trees.behaviour.Behaviour, show_status: bool = False, show_reasons: bool = True, show_ports: bool = False
) -> str:
    """The tree as indented unicode lines; optionally with statuses, the reason each node is there and ports."""
    lines: list[str] = []

    def visit(node: py_trees.behaviour.Behaviour, prefix: str, last: bool, top: bool) -> None:
        branch = "" if top else ("└── " if last else "├── ")
        text = _label(node)
        if show_status:
            text = f"{_STATUS_MARK[node.status]} {text}"
            if node.feedback_message and node.status is Status.FAILURE:
                text += f"  -- {node.feedback_message}"
        if show_ports and isinstance(node, Annotator):
            ins = ", ".join(t.__name__ for t in node.inputs) or "-"
            outs = ", ".join(t.__name__ for t in node.outputs) or "-"
            text += f"  ({ins} → {outs})"
        reason = reason_of(node)
        if show_reasons and reason:
            text += f"  # {reason}"
        lines.append(prefix + branch + text)
        children = list(node.children)
        child_prefix = prefix if top else prefix + ("    " if last else "│   ")
        for index, child in enumerate(children):
            visit(child, child_prefix, index == len(children) - 1, False)

    visit(root, "", True, True)
    return "\n".join(lines)


_DOT_SHAPES = {
    "Pipeline": ("box3d", "#cde6f7"),
    "Sequence": ("box", "#f2a65a"),
    "Fallback": ("octagon", "#c7e9c0"),
    "Parallel": ("parallelogram", "#fdd0a2"),
    "Slot": ("box", "#eeeeee"),
    "Annotator": ("ellipse", "#ffffff"),
    "Decorator": ("house", "#dddddd"),
    "Loop": ("house", "#cde8f7"),
    "Behaviour": ("ellipse", "#ffffff"),
}


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def dot_tree(root: py_trees.behaviour.Behaviour) -> str:
    """The tree as a Graphviz dot digraph (reasons become tooltips)."""
    out = [
        "digraph ppt {",
        '  graph [rankdir=TB, fontname="Helvetica"];',
        '  node [fontname="Helvetica", style=filled];',
    ]
    ids: dict[int, str] = {}
    for index, node in enumerate(root.iterate()):
        ids[id(node)] = f"n{index}"
    for node in root.iterate():
        shape, fill = _DOT_SHAPES[node_kind(node)]
        attributes = f"label={_quote(_label(node))}, shape={shape}, fillcolor={_quote(fill)}"
        reason = reason_of(node)
        if reason:
            attributes += f", tooltip={_quote(reason)}"
        out.append(f"  {ids[id(node)]} [{attributes}];")
        for child in node.children:
            out.append(f"  {ids[id(node)]} -> {ids[id(child)]};")
    out.append("}")
    return "\n".join(out) + "\n"


def svg_tree(root: py_trees.behaviour.Behaviour) -> str:
    """The tree as SVG, rendered by Graphviz's ``dot``; raises RuntimeError when dot is not installed."""
    dot = shutil.which("dot")
    if dot is None:
        raise RuntimeError("Graphviz 'dot' is not installed (apt-get install graphviz); use --format dot or text")
    result = subprocess.run([dot, "-Tsvg"], input=dot_tree(root), capture_output=True, text=True, check=True)
    return result.stdout


def stats_table(root: py_trees.behaviour.Behaviour) -> str:
    """Per-annotator run counts, median and max run times as a text table."""
    rows = [("annotator", "runs", "median ms", "max ms")]
    for node in root.iterate():
        if isinstance(node, Annotator):
            stats = node.stats
            rows.append(
                (node.name, str(stats.count), f"{stats.median_seconds * 1e3:.2f}", f"{stats.max_seconds * 1e3:.2f}")
            )
    widths = [max(len(row[i]) for row in rows) for i in range(4)]
    lines = []
    for row in rows:
        pairs = enumerate(zip(row, widths, strict=True))
        cells = [cell.ljust(width) if i == 0 else cell.rjust(width) for i, (cell, width) in pairs]
        lines.append("  ".join(cells))
    return "\n".join(lines)


def tree_to_dict(root: py_trees.behaviour.Behaviour) -> dict[str, object]:
    """A machine-readable tree: node type, name, annotator class, reason and children."""
    node: dict[str, object] = {"type": node_kind(root), "name": root.name}
    if isinstance(root, Annotator):
        node["class"] = f"{type(root).__module__}.{type(root).__name__}"
        node["inputs"] = [t.__name__ for t in root.inputs]
        node["outputs"] = [t.__name__ for t in root.outputs]
    if isinstance(root, ThresholdParallel):
        node["n_success"] = root.n_success
        node["n_failure"] = root.n_failure
    if isinstance(root, Loop):
        node["runs"] = root.runs
        node["max_failures"] = root.max_failures
    node["reason"] = reason_of(root)
    if root.children:
        node["children"] = [tree_to_dict(child) for child in root.children]
    return node
