"""The native vector env: make_vec, equivalence with single envs, threads, the GIL."""

from __future__ import annotations

import threading
import time

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import unforeseen


def test_make_vec_returns_the_native_vector_env():
    envs = gym.make_vec("unforeseen/Jaywalk-v0", num_envs=4, vectorization_mode="vector_entry_point")
    assert isinstance(envs, unforeseen.VectorEnv)
    assert isinstance(envs, gym.vector.VectorEnv)
    assert envs.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    obs, info = envs.reset(seed=0)
    assert obs.shape == (4, 4) and obs in envs.observation_space
    obs, rewards, terminated, truncated, info = envs.step(envs.action_space.sample())
    assert rewards.shape == (4,) and terminated.dtype == np.bool_ and info["state"].shape == (4, 4)


@pytest.mark.parametrize("observation", ["discrete", "kinematic"])
def test_vector_env_equals_single_envs_step_for_step(observation):
    n, seed, steps = 5, 11, 120
    rng = np.random.default_rng(1)
    actions = rng.integers(0, 3, size=(steps, n))
    vec = unforeseen.VectorEnv("two_pedestrians", n, observation)
    singles = [unforeseen.make_env("two_pedestrians", observation) for _ in range(n)]
    vobs, _ = vec.reset(seed=seed)
    sobs = [env.reset(seed=seed + i)[0] for i, env in enumerate(singles)]
    np.testing.assert_array_equal(vobs, np.stack(sobs))
    ended = [False] * n
    resets = 0
    for t in range(steps):
        vobs, vrew, vterm, vtrunc, vinfo = vec.step(actions[t])
        for i, env in enumerate(singles):
            if ended[i]:  # NEXT_STEP autoreset: this step resets env i
                obs, info = env.reset()
                rew, term, trunc = 0.0, False, False
                ended[i] = False
                resets += 1
            else:
                obs, rew, term, trunc, info = env.step(int(actions[t, i]))
                ended[i] = term or trunc
            np.testing.assert_array_equal(vobs[i], obs)
            assert (vrew[i], vterm[i], vtrunc[i]) == (rew, term, trunc)
            assert tuple(vinfo["state"][i]) == info["state"]
            assert vinfo["light"][i] == info["light"]
            assert vinfo["reward_terms"]["progress"][i] == info["reward_terms"]["progress"]
    assert resets > n  # several episodes each


@pytest.mark.parametrize("observation", ["discrete", "kinematic"])
def test_vector_env_equals_gymnasiums_sync_vector_env(observation):
    """Gymnasium's own vectorizer over the single envs is the reference: the same
    observations, rewards, flags and autoreset (NEXT_STEP) step for step."""
    n, steps = 4, 150
    actions = np.random.default_rng(2).integers(0, 3, size=(steps, n))
    ours = unforeseen.VectorEnv("jaywalk", n, observation)
    ref = gym.vector.SyncVectorEnv(
        [lambda: unforeseen.make_env("jaywalk", observation) for _ in range(n)],
        autoreset_mode=AutoresetMode.NEXT_STEP,
    )
    assert ours.single_observation_space == ref.single_observation_space
    assert ours.single_action_space == ref.single_action_space
    assert ours.observation_space == ref.observation_space
    o1, _ = ours.reset(seed=5)
    o2, _ = ref.reset(seed=5)
    np.testing.assert_array_equal(o1, o2)
    for t in range(steps):
        a = ours.step(actions[t])
        b = ref.step(actions[t])
        for x, y in zip(a[:4], b[:4]):
            np.testing.assert_array_equal(x, y)
    ref.close()


def test_results_do_not_depend_on_the_number_of_threads():
    def run(threads):
        vec = unforeseen.VectorEnv("jaywalk", 16, "kinematic", num_threads=threads)
        out = [vec.reset(seed=3)[0]]
        for t in range(60):
            out.append(vec.step(np.full(16, t % 3))[0])
        return np.stack(out)

    np.testing.assert_array_equal(run(1), run(2))


def test_a_python_thread_runs_while_a_large_vector_step_runs():
    vec = unforeseen.VectorEnv("jaywalk", 512, num_threads=1)
    vec.reset(seed=0)
    actions = np.ones(512, dtype=np.int64)
    ticks = 0
    stop = threading.Event()

    def count():
        nonlocal ticks
        while not stop.is_set():
            ticks += 1
            time.sleep(0.0005)

    thread = threading.Thread(target=count)
    started = time.perf_counter()
    thread.start()
    before = ticks
    for _ in range(3):
        vec.step(actions)
    elapsed = time.perf_counter() - started
    during = ticks - before
    stop.set()
    thread.join()
    # Three steps of 512 envs take tens of milliseconds; with the GIL held the counter
    # could not advance at all while Rust runs.
    assert elapsed > 0.01
    assert during >= 5, (during, elapsed)


def test_bad_vector_input():
    vec = unforeseen.VectorEnv("jaywalk", 3)
    with pytest.raises(RuntimeError, match="before reset"):
        vec.step(np.zeros(3, dtype=np.int64))
    vec.reset(seed=0)
    with pytest.raises(ValueError, match="action 3"):
        vec.step(np.array([0, 3, 1]))
    with pytest.raises(ValueError, match="2 actions for 3 envs"):
        vec.step(np.array([0, 1]))
    with pytest.raises(ValueError, match="num_envs"):
        unforeseen.VectorEnv("jaywalk", 0)


@pytest.mark.parametrize("actions", [[1.7, 0.2, 1.0], [np.nan, 0, 1], np.array([1.0, 0.0, 2.0], dtype=np.float32)])
def test_float_actions_are_refused_as_by_the_single_env(actions):
    single = unforeseen.make_env("jaywalk")
    single.reset(seed=0)
    with pytest.raises(TypeError):
        single.step(1.7)
    vec = unforeseen.VectorEnv("jaywalk", 3)
    vec.reset(seed=0)
    with pytest.raises(TypeError, match="integers"):
        vec.step(actions)
    # Integers of any width are fine.
    vec.step(np.array([1, 0, 2], dtype=np.uint8))
    vec.step([1, 0, 2])


@pytest.mark.parametrize("observation", ["discrete", "kinematic"])
def test_same_step_autoreset_equals_gymnasiums_sync_vector_env(observation):
    n, steps = 4, 120
    actions = np.random.default_rng(3).integers(0, 3, size=(steps, n))
    ours = unforeseen.VectorEnv("jaywalk", n, observation, autoreset_mode=AutoresetMode.SAME_STEP)
    assert ours.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    ref = gym.vector.SyncVectorEnv(
        [lambda: unforeseen.make_env("jaywalk", observation) for _ in range(n)],
        autoreset_mode=AutoresetMode.SAME_STEP,
    )
    np.testing.assert_array_equal(ours.reset(seed=8)[0], ref.reset(seed=8)[0])
    ended = 0
    for t in range(steps):
        a = ours.step(actions[t])
        b = ref.step(actions[t])
        for x, y in zip(a[:4], b[:4]):
            np.testing.assert_array_equal(x, y)
        ia, ib = a[4], b[4]
        done = a[2] | a[3]
        if done.any():
            ended += int(done.sum())
            np.testing.assert_array_equal(ia["_final_obs"], ib["_final_obs"])
            for i in np.flatnonzero(done):
                np.testing.assert_array_equal(ia["final_obs"][i], ib["final_obs"][i])
                assert ia["final_info"]["goal"][i] == ib["final_info"]["goal"][i]
                assert ia["final_info"]["step"][i] == ib["final_info"]["step"][i]
        np.testing.assert_array_equal(ia["step"], ib["step"])  # the reset's info for ended envs
    assert ended > n
    ref.close()


def test_get_attr_set_attr_and_call():
    vec = unforeseen.VectorEnv("two_pedestrians", 3)
    assert vec.get_attr("map_name") == ("two_pedestrians",) * 3
    assert vec.get_attr("observation_space") == (vec.single_observation_space,) * 3
    assert vec.get_attr("render_mode") == (None, None, None)
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        vec.get_attr("nope")
    vec.set_attr("tag", ["a", "b", "c"])
    assert vec.get_attr("tag") == ("a", "b", "c")
    vec.set_attr("weight", 2.0)
    assert vec.call("weight") == (2.0, 2.0, 2.0)
    vec.set_attr("double", [lambda x, k=k: k * x for k in range(3)])
    assert vec.call("double", 5) == (0, 5, 10)
    with pytest.raises(ValueError, match="2 values for 3 envs"):
        vec.set_attr("tag", ["a", "b"])
    with pytest.raises(AttributeError, match="new VectorEnv"):
        vec.set_attr("render_mode", "rgb_array")
    with pytest.raises(AttributeError, match="stepped together"):
        vec.call("step", 0)
    assert vec.call("map_name") == ("two_pedestrians",) * 3


# Steps a vector env of many envs until Ctrl-C (SIGINT from a timer thread, at a random
# moment); prints the exception's type. With `first`, the signal falls within the first
# milliseconds of stepping a fresh interpreter, when the NumPy calls are made the first time.
CTRL_C_WHILE_STEPPING = r"""
import os, random, signal, sys, threading, time
import numpy as np
import unforeseen

tries, first = int(sys.argv[1]), sys.argv[2] == "first"
rng = random.Random(int(sys.argv[3]))
vec = unforeseen.VectorEnv("jaywalk", 64, num_threads=2)
vec.reset(seed=1)
actions = np.ones(vec.num_envs, dtype=np.int64)
seen = []
for _ in range(tries):
    delay = rng.uniform(0.0, 0.002 if first else 0.03)
    try:
        threading.Timer(delay, os.kill, (os.getpid(), signal.SIGINT)).start()
        start = time.monotonic()
        while time.monotonic() - start < 5.0:
            vec.step(actions)
        seen.append("none")
    except BaseException as e:
        seen.append(type(e).__name__)
print(" ".join(seen))
"""


def _ctrl_c_while_stepping(tries: int, when: str, seed: int) -> list[str]:
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", CTRL_C_WHILE_STEPPING, str(tries), when, str(seed)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout.split()


def test_ctrl_c_while_stepping_a_vector_env_raises_keyboard_interrupt():
    """Issue 49: Ctrl-C while stepping ``VectorEnv`` once raised ``PanicException`` (a NumPy
    call failing on the pending signal) instead of ``KeyboardInterrupt``. 200 signals at
    random moments in one interpreter, and 10 in the first steps of a fresh one each."""
    seen = _ctrl_c_while_stepping(200, "any", seed=1)
    for k in range(10):
        seen += _ctrl_c_while_stepping(1, "first", seed=100 + k)
    assert len(seen) == 210
    assert set(seen) == {"KeyboardInterrupt"}, {name: seen.count(name) for name in set(seen)}


def test_import_sets_up_every_numpy_call_a_step_makes():
    """What the numpy crate would set up on the first step (its C API, its shared borrow
    checking, whose set-up runs Python code a pending Ctrl-C interrupts) is set up when
    ``unforeseen`` is imported, so no step meets a set-up that fails on a signal."""
    import subprocess
    import sys

    probe = ("import numpy, unforeseen; "
             "print(hasattr(numpy._core.multiarray, '_RUST_NUMPY_BORROW_CHECKING_API'))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=60)
    assert done.stdout.split() == ["True"], done.stdout + done.stderr
