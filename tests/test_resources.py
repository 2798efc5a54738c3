"""Shared resources: built once per key for every tree that shares the pool; a failed build is tried again."""

from __future__ import annotations

import threading

import pytest

from robokudo.core.resources import SharedResources


def test_a_resource_is_built_once_even_when_many_threads_ask_at_once() -> None:
    pool = SharedResources()
    builds: list[int] = []

    def build() -> object:
        builds.append(1)
        return object()

    found: list[object] = []
    threads = [threading.Thread(target=lambda: found.append(pool.get("model", build))) for _ in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(builds) == 1 and len({id(x) for x in found}) == 1
    assert pool.get("other", object) is not found[0] and len(pool) == 2


def test_a_failed_build_stores_nothing_and_the_next_request_builds_again() -> None:
    pool = SharedResources()

    def broken() -> object:
        raise OSError("model file is truncated")

    with pytest.raises(OSError, match="truncated"):
        pool.get("model", broken)
    assert len(pool) == 0
    assert pool.get("model", lambda: "loaded") == "loaded"
