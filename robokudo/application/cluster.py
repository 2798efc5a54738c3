"""The Ray cluster the commands use for remote experts and parallel evaluation.

:func:`ray_cluster` connects to the cluster at an address (``ray://HOST:10001`` through the Ray client, or
``HOST:6379`` / ``auto`` for a node of the cluster), or starts a local one on this machine (the default) with
the given number of CPUs (its workers at this process's priority: :data:`LOCAL_SYSTEM_CONFIG`), and
disconnects (stopping a local one) afterwards. When this process is connected
already (a program or a test that called ``ray.init``), that connection is used and left open.

Ray is an optional extra (``pip install 'robokudo[ray]'``); without it :class:`ClusterError` says so.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from types import ModuleType

from robokudo.core.remote import INSTALL_HINT, PlacementError, require_ray

LOCAL_SYSTEM_CONFIG = {"worker_niceness": 0}
"""Ray's settings for a local cluster: its workers run at this process's priority (Ray's default lowers them by
15, so on a busy machine every other program would go before the scenes and experts this command waits for)."""


class ClusterError(Exception):
    """No cluster to work on: Ray is missing or the address cannot be reached (the message says which)."""


def ray_module(purpose: str = "this") -> ModuleType:
    """The ``ray`` module; ClusterError (``PURPOSE needs Ray``, with the install hint) without it."""
    try:
        return require_ray()
    except PlacementError:
        raise ClusterError(f"{purpose} needs Ray. {INSTALL_HINT}") from None


@contextmanager
def ray_cluster(address: str | None = None, num_cpus: int | None = None, purpose: str = "this") -> Iterator[ModuleType]:
    """Connected to the cluster at ``address`` (None: a new local cluster with ``num_cpus`` CPUs) for the block;
    yields the ``ray`` module. ClusterError without Ray (``PURPOSE needs Ray``) or when the cluster cannot be
    reached."""
    ray = ray_module(purpose)
    if ray.is_initialized():
        yield ray
        return
    options: dict[str, object] = {"include_dashboard": False, "log_to_driver": False, "logging_level": logging.ERROR}
    if address is None:
        options["num_cpus"] = num_cpus
        options["_system_config"] = LOCAL_SYSTEM_CONFIG
    try:
        ray.init(address=address, **options)
    except (ConnectionError, RuntimeError, ValueError) as error:
        raise ClusterError(f"cannot connect to the Ray cluster at {address}: {error}") from None
    try:
        yield ray
    finally:
        ray.shutdown()
