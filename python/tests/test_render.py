"""Rendering as Gymnasium users expect it: readable frames, render_fps, "human" through
the render extra (pygame), RecordVideo to mp4 (the video extra), the vector env's frames."""

from __future__ import annotations

import os
import sys

import gymnasium as gym
import numpy as np
import pytest

import unforeseen

# The colours render.rs paints (RGB).
CAR = (40, 90, 220)
CROSSWALK = (240, 240, 240)
ON_CROSSWALK = (250, 120, 20)
OFF_CROSSWALK = (230, 60, 160)


def _pixels(frame: np.ndarray, rgb: tuple[int, int, int]) -> np.ndarray:
    return np.all(frame == np.array(rgb, dtype=np.uint8), axis=-1)


def _frame_with_pedestrian(env: gym.Env) -> np.ndarray:
    """The first frame of the seeded episode with a pedestrian on the crosswalk."""
    env.reset(seed=3)
    for _ in range(200):
        _, _, term, trunc, info = env.step(0)
        if info["state"][3] == 1:
            return env.render()
        if term or trunc:
            env.reset()
    raise AssertionError("no pedestrian on the crosswalk in 200 ticks")


def test_rgb_array_frames_are_readable():
    env = gym.make("unforeseen/Intersection-v0", render_mode="rgb_array")
    assert env.metadata["render_fps"] == 1.0  # one frame per 1 s decision tick
    frame = _frame_with_pedestrian(env)
    h, w, c = frame.shape
    assert w >= 960 and h >= 120 and c == 3 and frame.dtype == np.uint8
    assert w % 2 == 0 and h % 2 == 0  # video encoders need even sides
    # The car is a solid blue box of about 4.5 m x 1.8 m at 10 px/m.
    ys, xs = np.nonzero(_pixels(frame, CAR))
    assert 35 <= xs.max() - xs.min() + 1 <= 50 and 12 <= ys.max() - ys.min() + 1 <= 20
    # The zebra crosswalk: several white stripes across the road.
    assert _pixels(frame, CROSSWALK).sum() > 500
    # A pedestrian on the crosswalk: an orange disc some pixels across.
    ys, xs = np.nonzero(_pixels(frame, ON_CROSSWALK))
    assert len(xs) >= 20 and xs.max() - xs.min() + 1 >= 6


def test_render_fps_follows_the_decision_tick():
    env = unforeseen.make_env("jaywalk", render_mode="rgb_array", decision_dt=0.5)
    assert env.metadata["render_fps"] == 2.0


def test_human_mode_without_pygame_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "pygame", None)  # import pygame raises ImportError
    with pytest.raises(gym.error.DependencyNotInstalled, match=r"unforeseen\[render\]"):
        unforeseen.make_env("jaywalk", render_mode="human")
    with pytest.raises(gym.error.DependencyNotInstalled, match=r"unforeseen\[render\]"):
        gym.make("unforeseen/Jaywalk-v0", render_mode="human")


def test_human_mode_draws_a_window(monkeypatch):
    pygame = pytest.importorskip("pygame", reason="the render extra (pygame) is not installed")
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    env = gym.make("unforeseen/Jaywalk-v0", render_mode="human")
    env.unwrapped.metadata["render_fps"] = 1000  # do not wait a second per tick here
    env.reset(seed=0)
    for _ in range(3):
        env.step(1)
    surface = pygame.display.get_surface()
    assert surface.get_size() == (1076, 130)
    # The window shows the env's frame.
    shown = pygame.surfarray.array3d(surface).swapaxes(0, 1)
    np.testing.assert_array_equal(shown, env.unwrapped._env.render_rgb(10.0))
    env.close()
    assert not pygame.display.get_init()


def test_a_headless_check_of_human_mode_is_quiet():
    # pygame.init() opened the audio device too: 8 ALSA lines on a machine without sound.
    pytest.importorskip("pygame", reason="the render extra (pygame) is not installed")
    import subprocess

    code = (
        "import gymnasium as gym, unforeseen\n"
        "from gymnasium.utils.env_checker import check_env\n"
        "check_env(gym.make('unforeseen/Jaywalk-v0', render_mode='human').unwrapped)\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("XDG_RUNTIME_DIR", "SDL_AUDIODRIVER")}
    env["SDL_VIDEODRIVER"] = "dummy"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "ALSA" not in run.stderr and "XDG_RUNTIME_DIR" not in run.stderr, run.stderr


@pytest.mark.filterwarnings("ignore::DeprecationWarning")
@pytest.mark.filterwarnings("ignore::UserWarning")
def test_record_video_writes_an_episode_to_mp4(tmp_path):
    pytest.importorskip("moviepy", reason="the video extra (moviepy) is not installed")
    import imageio_ffmpeg

    env = gym.make("unforeseen/Jaywalk-v0", render_mode="rgb_array")
    env = gym.wrappers.RecordVideo(env, str(tmp_path), episode_trigger=lambda ep: ep == 0, disable_logger=True)
    env.reset(seed=1)
    ticks = 0
    while True:
        _, _, term, trunc, _ = env.step(1)
        ticks += 1
        if term or trunc:
            break
    env.close()
    videos = sorted(tmp_path.glob("*.mp4"))
    assert len(videos) == 1
    frames, _ = imageio_ffmpeg.count_frames_and_secs(str(videos[0]))
    assert frames == ticks + 1  # the reset's frame, then one per tick


def test_the_vector_env_renders_like_gymnasiums():
    vec = unforeseen.VectorEnv("jaywalk", 3, render_mode="rgb_array")
    assert vec.metadata["render_modes"] == ["rgb_array"] and vec.render_mode == "rgb_array"
    with pytest.raises(RuntimeError, match="reset"):
        vec.render()
    vec.reset(seed=4)
    for _ in range(5):
        vec.step(np.array([1, 0, 2]))
    frames = vec.render()
    # A tuple of frames, one per env, as SyncVectorEnv over the single envs gives them.
    ref = gym.vector.SyncVectorEnv(
        [lambda: unforeseen.make_env("jaywalk", render_mode="rgb_array") for _ in range(3)],
        autoreset_mode=gym.vector.AutoresetMode.NEXT_STEP,
    )
    ref.reset(seed=4)
    for _ in range(5):
        ref.step(np.array([1, 0, 2]))
    expected = ref.render()
    assert isinstance(frames, tuple) and len(frames) == 3
    for ours, theirs in zip(frames, expected):
        np.testing.assert_array_equal(ours, theirs)
    assert not np.array_equal(frames[0], frames[1])  # different actions, different frames
    assert len(vec.call("render")) == 3
    assert unforeseen.VectorEnv("jaywalk", 2).render() is None
    with pytest.raises(ValueError, match="HumanRendering"):
        unforeseen.VectorEnv("jaywalk", 2, render_mode="human")
    ref.close()


def test_saves_a_frame_as_png(tmp_path):
    """The frame a reader looks at (UNFORESEEN_FRAME_PNG=path keeps it)."""
    pil = pytest.importorskip("PIL.Image", reason="Pillow is not installed")
    env = unforeseen.make_env("intersection", render_mode="rgb_array")
    frame = _frame_with_pedestrian(env)
    path = os.environ.get("UNFORESEEN_FRAME_PNG") or str(tmp_path / "frame.png")
    pil.fromarray(frame).save(path)
    with pil.open(path) as back:
        assert back.size == (frame.shape[1], frame.shape[0])
        np.testing.assert_array_equal(np.asarray(back.convert("RGB")), frame)
