"""Helpers of the reasoning tests: small Turtle files layered over or replacing shipped ones."""

from __future__ import annotations

from pathlib import Path

from ontology import shipped_files


def write_ttl(path: Path, body: str) -> Path:
    """Write a Turtle file with the usual prefixes; returns its path."""
    prefixes = (
        "@prefix rk: <http://robokudo.org/ontology#> .\n"
        "@prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
        "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
        "@prefix skos: <http://www.w3.org/2004/02/skos/core#> .\n\n"
    )
    path.write_text(prefixes + body, encoding="utf-8")
    return path


def shipped_without(name: str) -> list[Path]:
    """The shipped files except the one called ``name``."""
    return [p for p in shipped_files() if p.name != name]
