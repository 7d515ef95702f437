"""Shared fixtures: one small trained agent for the whole session (300 episodes)."""

from __future__ import annotations

from pathlib import Path

import pytest

import unforeseen

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _in_a_fresh_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every test runs in its own empty folder: what a job writes at its default place
    (``out/eval``, ``out/compare``, ``results.jsonl``) stays out of the repository."""
    monkeypatch.chdir(tmp_path)


@pytest.fixture(scope="session")
def agent() -> unforeseen.Agent:
    return unforeseen.train("intersection", episodes=300, seed=7)


@pytest.fixture(scope="session")
def agent_file(agent: unforeseen.Agent, tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("agent") / "agent.ron"
    agent.save(str(path))
    return path
