"""The layer contracts (import-linter, configured in pyproject.toml) hold, and the check is live."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")


def lint_imports(project: Path) -> subprocess.CompletedProcess[str]:
    """Run lint-imports on ``project`` (its own packages first on the path, no cache)."""
    environment = {**os.environ, "PYTHONPATH": str(project)}
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache"], cwd=project, env=environment, capture_output=True, text=True, check=False
    )


def test_every_layer_contract_is_kept() -> None:
    result = lint_imports(ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


@pytest.mark.parametrize(
    ("module", "line", "contract"),
    [
        ("robokudo/core/wrong.py", "import reasoning.knowledge.knowledge_base", "Layers point down"),
        ("reasoning/wrong.py", "import annotators.catalog", "Layers point down"),
        ("annotators/wrong.py", "import trees.synthesis", "Layers point down"),
        ("queries/wrong.py", "import robokudo.core.types", "Layers point down"),
        ("trees/wrong.py", "import robokudo.application.service", "Layers point down"),
        ("reasoning/planning/wrong.py", "import open3d", "free of vision libraries"),
    ],
)
def test_a_wrong_import_is_reported(tmp_path: Path, module: str, line: str, contract: str) -> None:
    project = tmp_path / "project"
    for name in ("robokudo", "queries", "reasoning", "annotators", "trees", "ontology"):
        shutil.copytree(ROOT / name, project / name, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", project / "pyproject.toml")
    (project / module).write_text(f'"""A module that breaks a layer."""\n\n{line}\n')
    result = lint_imports(project)
    assert result.returncode != 0
    assert f"{contract}" in result.stdout and "BROKEN" in result.stdout
    assert module.removesuffix(".py").replace("/", ".") in result.stdout
