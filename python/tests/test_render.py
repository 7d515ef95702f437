"""Rendering as Gymnasium users expect it: readable frames, render_fps, "human" through
the render extra (pygame), RecordVideo to mp4 (the video extra), the vector env's frames;
the straight road's frames as they always were, and a junction's with its cross street,
signal heads and vehicles."""

from __future__ import annotations

import os
import sys

import gymnasium as gym
import numpy as np
import pytest

import unforeseen

from conftest import REPO

# The colours render.rs paints (RGB).
CAR = (40, 90, 220)
CROSSWALK = (240, 240, 240)
ON_CROSSWALK = (250, 120, 20)
OFF_CROSSWALK = (230, 60, 160)
VEHICLE = (20, 150, 140)
VEHICLE_IN_PATH = (200, 30, 90)
RED = (220, 30, 30)
GREEN = (40, 200, 60)


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


def test_the_straight_road_frames_are_as_they_were():
    """Maps without a junction draw as before there were junctions: the frames of a few
    seeded episodes hash to the digest taken before the junction was drawn (a change of
    tiny-skia or of the straight road's drawing shows here too)."""
    import hashlib

    digest = hashlib.sha256()
    for name in ["jaywalk", "intersection", str(REPO / "maps" / "ice_before_crosswalk.ron"), "two_pedestrians"]:
        env = unforeseen.make_env(name, render_mode="rgb_array")
        env.reset(seed=3)
        for k in range(12):
            digest.update(env.render().tobytes())
            _, _, term, trunc, _ = env.step(k % 3)
            if term or trunc:
                break
        digest.update(env.render().tobytes())
    assert digest.hexdigest() == "1c0123b0b69e35a75fff9c32ea6ff3d242e36769d771612f244ba741ce7e3885"


def test_a_junction_frame_shows_the_cross_street_the_heads_and_the_vehicle():
    """Speeding up on red_runner meets the car that runs its red from the south arm in
    the box: the frame reaches along the cross street, the runner is drawn in the car's
    path inside the box, the cross street's heads show red and the car's green."""
    env = unforeseen.make_env(str(REPO / "maps" / "junction" / "red_runner.ron"), render_mode="rgb_array")
    env.reset(seed=7)
    while True:
        _, _, term, trunc, info = env.step(1)
        if term or trunc:
            break
    assert info["collision"]
    frame = env.render()
    h, w, _ = frame.shape
    # 25.5 m either side of the road at 10 px/m: the box (x 69..76, y -3.5..3.5) lies at
    # columns 755..825 and rows 220..290 (x from -6.5 m, y down from 25.5 m).
    assert (h, w) == (510, 1076)
    px = lambda x: round((x + 6.5) * 10)  # noqa: E731
    py = lambda y: round((25.5 - y) * 10)  # noqa: E731
    box = frame[py(3.5) : py(-3.5), px(69.0) : px(76.0)]
    assert _pixels(box, VEHICLE_IN_PATH).sum() > 300
    assert _pixels(frame, VEHICLE_IN_PATH).sum() == _pixels(box, VEHICLE_IN_PATH).sum()
    # The cross street's asphalt north and south of the road, as the road's.
    road = tuple(frame[py(-1.0), px(20.0)])
    assert tuple(frame[py(15.0), px(71.0)]) == road and tuple(frame[py(-15.0), px(74.0)]) == road
    # The south arm's head (east kerb, 1 m before its stop line at y = -4.5) red; the
    # car's green.
    assert tuple(frame[py(-5.5), px(77.0)]) == RED
    assert tuple(frame[py(-4.5), px(63.0)]) == GREEN
    line = env.unwrapped._env.render_ansi()
    assert "+" in line and "V" in line and line.endswith(", cross red, 1 vehicle (1 in path)"), line
