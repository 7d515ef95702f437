"""The Gymnasium environments: registration, check_env on every embedded map in both
observation forms and both render modes, spaces, seeding, overrides, rendering."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import unforeseen

MAPS = unforeseen.embedded_maps()


def test_every_embedded_map_is_registered():
    assert len(MAPS) >= 10
    for name in MAPS:
        assert unforeseen.env_id(name) in gym.registry
    assert unforeseen.env_id("jaywalk_late") == "unforeseen/JaywalkLate-v0"
    env = gym.make("unforeseen/Intersection-v0")
    assert env.unwrapped.map_name == "intersection"


@pytest.mark.parametrize("map_name", MAPS)
@pytest.mark.parametrize("observation", ["discrete", "kinematic"])
@pytest.mark.parametrize("render_mode", ["rgb_array", "ansi"])
def test_check_env(map_name, observation, render_mode):
    env = gym.make(unforeseen.env_id(map_name), observation=observation, render_mode=render_mode)
    check_env(env.unwrapped, skip_render_check=False)
    env.close()


@pytest.mark.parametrize("map_name", MAPS)
@pytest.mark.parametrize("observation", ["discrete", "kinematic"])
def test_observations_stay_in_their_space_for_whole_episodes(map_name, observation):
    env = unforeseen.make_env(map_name, observation)
    rng = np.random.default_rng(0)
    for episode in range(3):
        obs, info = env.reset(seed=episode)
        assert obs in env.observation_space, (obs, env.observation_space)
        while True:
            obs, reward, terminated, truncated, info = env.step(int(rng.integers(3)))
            assert obs in env.observation_space, (obs, env.observation_space)
            terms = info["reward_terms"]
            assert reward == pytest.approx(terms["progress"] + terms["time"] + terms["goal"] + terms["crash"])
            if terminated or truncated:
                assert terminated == (info["goal"] or info["collision"])
                assert truncated == info["timeout"]
                break


def rollout(env, seed, actions=None):
    obs, _ = env.reset(seed=seed)
    trace = [obs.tolist()]
    for t in range(200):
        obs, r, term, trunc, info = env.step(1 if actions is None else actions[t % len(actions)])
        trace.append((obs.tolist(), r, term, trunc, info["state"], info["light"]))
        if term or trunc:
            obs, _ = env.reset()
            trace.append(obs.tolist())
    return trace


@pytest.mark.parametrize("observation", ["discrete", "kinematic"])
def test_seeded_reset_then_reset_is_reproducible(observation):
    a = rollout(unforeseen.make_env("intersection", observation), seed=3, actions=[1, 0, 2, 1])
    b = rollout(unforeseen.make_env("intersection", observation), seed=3, actions=[1, 0, 2, 1])
    c = rollout(unforeseen.make_env("intersection", observation), seed=4, actions=[1, 0, 2, 1])
    assert a == b
    assert a != c


def test_world_seed_option_runs_that_world_exactly():
    env = unforeseen.make_env("intersection")
    first = env.reset(options={"world_seed": 12345})
    again = env.reset(seed=9, options={"world_seed": 12345})
    assert first[0].tolist() == again[0].tolist() and first[1] == again[1]


def test_spaces_match_the_rust_core():
    env = unforeseen.make_env("jaywalk")
    assert env.action_space == gym.spaces.Discrete(3)
    assert env.observation_space == gym.spaces.MultiDiscrete([4, 4, 2, 2])
    kin = unforeseen.make_env("jaywalk", "kinematic", pedestrian_slots=2)
    assert kin.observation_space.shape == (7 + 5 * 2,)
    assert kin.observation_space.dtype == np.float32
    obs, _ = kin.reset(seed=0)
    assert obs[0] == pytest.approx(0.0) and obs[1] == pytest.approx(3.0)  # start_x, start_speed


def test_map_overrides_go_through_the_map_loader():
    env = unforeseen.make_env("jaywalk", max_steps=5)
    env.reset(seed=0)
    for t in range(5):
        _, _, terminated, truncated, info = env.step(0)
        if terminated:
            break
    assert truncated and info["timeout"] and info["step"] == 5
    # Overriding with the map's own values changes nothing.
    same = unforeseen.make_env("jaywalk", max_steps=40, lane_width=3.5, episode__decision_dt=1.0)
    assert rollout(same, seed=5) == rollout(unforeseen.make_env("jaywalk"), seed=5)
    with pytest.raises(ValueError, match="episode.max_steps"):
        unforeseen.make_env("jaywalk", max_steps=0)
    with pytest.raises(ValueError, match="no such field"):
        unforeseen.make_env("jaywalk", no_such_field=1)
    with pytest.raises(ValueError, match="section__width"):
        unforeseen.make_env("jaywalk", width=1.0)
    # A name the optional junction shares with the road is the road's; the junction's
    # is written with its section, and gives the map a junction.
    with pytest.raises(ValueError, match=r"\(overrides\): junction\.lane_width: "):
        unforeseen.make_env("jaywalk", junction__lane_width=-1.0)
    with pytest.raises(ValueError, match=r"\(overrides\): road\.lane_width: "):
        unforeseen.make_env("jaywalk", lane_width=-1.0)


def test_render_modes():
    env = unforeseen.make_env("jaywalk", render_mode="rgb_array")
    env.reset(seed=1)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert frame.shape[1] > frame.shape[0] > 20
    for _ in range(8):
        env.step(1)
    later = env.render()
    assert later.shape == frame.shape and not np.array_equal(later, frame)  # the car moved
    text = unforeseen.make_env("jaywalk", render_mode="ansi")
    text.reset(seed=1)
    line = text.render()
    assert isinstance(line, str) and "C" in line and "light" in line
    with pytest.raises(ValueError, match="render_mode"):
        unforeseen.make_env("jaywalk", render_mode="window")


def test_each_step_gets_its_own_info_dicts():
    """Infos are built from shared templates and shared state tuples: a caller that
    keeps or edits one step's info must not see it change, nor change the next one."""
    env = unforeseen.make_env("jaywalk")
    _, first = env.reset(seed=0)
    kept = {**first, "reward_terms": dict(first["reward_terms"])}
    first["collision"] = "edited"
    first["reward_terms"]["goal"] = 1e9
    _, _, _, _, second = env.step(1)
    assert second["collision"] is False and second["reward_terms"]["goal"] != 1e9
    assert second is not first and second["reward_terms"] is not first["reward_terms"]
    assert kept["state"] == first["state"] and isinstance(second["state"], tuple)
    assert list(second) == list(kept), "the keys keep their documented order"


def test_overrides_equal_the_same_values_in_a_map_file(tmp_path):
    """Overrides are laid over the loaded map as typed values (no map text written and
    parsed again): the map equals, field for field, the one a map file with `base:` and
    the same values loads to, and its episodes are the same, bit for bit."""
    import json

    overrides = dict(max_steps=30, lane_width=3.2, speed_edges=[0.5, 3.0, 6.0], offset="Random",
                     vehicle__start_speed=4, crosswalk__width=5)
    file = tmp_path / "over.ron"
    file.write_text('(base: "jaywalk", road: (lane_width: 3.2), bins: (speed_edges: [0.5, 3.0, 6.0]),\n'
                    ' light: (offset: Random), vehicle: (start_speed: 4), crosswalk: (width: 5),\n'
                    ' episode: (max_steps: 30))\n')
    given, written = unforeseen.make_env("jaywalk", **overrides), unforeseen.make_env(str(file))

    def fields(env):
        m = json.loads(env.unwrapped._env.map_json)
        return {k: v for k, v in m.items() if k not in ("name", "description", "base")}

    assert fields(given) == fields(written)
    assert fields(given) != fields(unforeseen.make_env("jaywalk"))
    for seed in (1, 2, 3):
        assert rollout(given, seed=seed, actions=[1, 1, 0, 2]) == rollout(written, seed=seed, actions=[1, 1, 0, 2])


@pytest.mark.parametrize(
    "overrides,message",
    [
        (dict(lane_width=[1.0, 2.0]), r"^jaywalk \(overrides\): road\.lane_width: Expected f64 but found a sequence"),
        (dict(speed_edges=[0.5, "x"]), r"^jaywalk \(overrides\): bins\.speed_edges: RON text inside a list"),
        (dict(offset="Randum"), r"^jaywalk \(overrides\):1:1: light\.offset: "),
        (dict(lanes=0), r"^jaywalk \(overrides\): road\.lanes: "),
    ],
)
def test_an_override_error_names_the_map_and_the_field(overrides, message):
    with pytest.raises(ValueError, match=message):
        unforeseen.make_env("jaywalk", **overrides)
