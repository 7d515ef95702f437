"""Shared fixtures: one small trained agent for the whole session (300 episodes)."""

from __future__ import annotations

from pathlib import Path

import pytest

import unforeseen

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def agent() -> unforeseen.Agent:
    return unforeseen.train("intersection", episodes=300, seed=7)


@pytest.fixture(scope="session")
def agent_file(agent: unforeseen.Agent, tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("agent") / "agent.ron"
    agent.save(str(path))
    return path
