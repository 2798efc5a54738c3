"""Where an annotator runs: in the tree's own process (the default) or on a Ray actor, with resource hints.

An annotator class declares it beside its ports and capability (``placement: ClassVar[Placement]``); a tree
builder or the ``--remote NAME`` option of ``run`` / ``query`` / ``serve`` can place any annotator remotely
without changing its class (:func:`robokudo.core.remote.place_remote`). The hints are Ray's scheduling
resources: the actor waits for a node with ``num_cpus`` CPUs and ``num_gpus`` GPUs free, and Ray restarts its
process up to ``max_restarts`` times (-1: always) when it dies. Calls go through a Ray compiled graph unless
``compiled_graph`` is False.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Placement:
    """An annotator's placement: ``remote`` on a Ray actor, with the resources the actor reserves."""

    remote: bool = False
    num_cpus: float = 1.0
    num_gpus: float = 0.0
    max_restarts: int = -1
    compiled_graph: bool = True
    """Call the actor through a Ray compiled graph (shared-memory channels) where Ray can; False: plain actor
    calls through Ray's object store."""

    def __post_init__(self) -> None:
        for name in ("num_cpus", "num_gpus"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or value < 0:
                raise ValueError(f"Placement.{name} must be a number >= 0, not {value!r}")
        if isinstance(self.max_restarts, bool) or not isinstance(self.max_restarts, int) or self.max_restarts < -1:
            raise ValueError(f"Placement.max_restarts must be a whole number >= -1, not {self.max_restarts!r}")

    def describe(self) -> str:
        """``local``, or ``remote (1 CPU, 1 GPU)``."""
        if not self.remote:
            return "local"
        gpus = f", {self.num_gpus:g} GPU" if self.num_gpus else ""
        return f"remote ({self.num_cpus:g} CPU{gpus})"
