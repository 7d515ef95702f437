"""Gymnasium environments of the unforeseen intersection (a Rapier 2D world in Rust)."""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import _unforeseen

__all__ = ["UnforeseenEnv", "ACTIONS", "LIGHTS", "episode_key"]

#: The three actions, by index.
ACTIONS = ("maintain", "speed up", "slow down")
#: Light phases by ``info["light_code"]``.
LIGHTS = ("green", "amber", "red")


def episode_key(np_random: np.random.Generator) -> int:
    """Draws the 64-bit key of an episode stream from ``np_random`` (one full-range uint64)."""
    return int(np_random.integers(0, 2**64, dtype=np.uint64))


class UnforeseenEnv(gym.Env):
    r"""A car approaching a signalised crosswalk, one decision tick at a time.

    ## Description

    The ego car drives along +x towards a destination line behind a crosswalk with a
    traffic light; pedestrians cross as the map says (on red in ``intersection``, on
    green in ``jaywalk``: the "unforeseen" event). Each step holds the chosen action
    for ``episode.decision_dt`` seconds (1 s by default) of Rapier sub-steps. All of it
    runs in Rust (``unforeseen_env::Env``, the loop the command line uses).

    ## Action Space

    ``Discrete(3)``, the longitudinal command held for one tick:

    | Num | Action    | Effect                                                  |
    |-----|-----------|---------------------------------------------------------|
    | 0   | maintain  | keep the current speed                                  |
    | 1   | speed up  | accelerate at ``vehicle.max_accel`` (3 m/s²) up to ``vehicle.max_speed`` (9 m/s) |
    | 2   | slow down | brake at ``vehicle.max_brake`` (3 m/s²), never below 0 m/s |

    ## Observation Space

    ``observation="discrete"`` (default): ``MultiDiscrete([n_d, n_v, 2, 2])``, int64, the
    paper's factors as the agent observes them (with the map's observation noise):

    | Num | Factor | Meaning                                                              |
    |-----|--------|----------------------------------------------------------------------|
    | 0   | d      | distance to the destination bin (0 arrived, 1 within 30 m, 2 30–60 m, 3 beyond 60 m by default) |
    | 1   | v      | speed bin (edges 0.5, 4.5, 7.5 m/s by default)                       |
    | 2   | L      | light: 0 red or amber, 1 green                                       |
    | 3   | p      | a pedestrian on the crosswalk: 0 no, 1 yes                           |

    ``observation="kinematic"``: ``Box(low, high, (7 + 5·P + 6·V,), float32)`` with ``P``
    pedestrian slots and ``V`` vehicle slots, and the bounds of
    ``unforeseen_env::kinematic::bounds`` (the map's ranges plus a 1-unit margin):

    | Index                     | Value                                          | Unit |
    |---------------------------|------------------------------------------------|------|
    | 0                         | x of the car's front bumper                    | m    |
    | 1                         | the car's speed along +x                       | m/s  |
    | 2                         | distance to the destination line (``goal_x - x``; <= 0 arrived) | m |
    | 3, 4, 5                   | light green, amber, red (one-hot)              | 0/1  |
    | 6                         | time until the light changes                   | s    |
    | 7+5k .. 11+5k             | pedestrian slot k: present, x, y, vx, vy       | 0/1, m, m, m/s, m/s |
    | 7+5P+6j .. 12+5P+6j       | vehicle slot j: present, x, y, vx, vy, heading | 0/1, m, m, m/s, m/s, rad |

    Coordinates: x along the road, y across it (the car's lane at negative y). Slot k is
    the k-th pedestrian in the world in order of appearance. Vehicle slot j is the j-th
    nearest other vehicle within 100 m (``unforeseen_env::kinematic::VEHICLE_RANGE``):
    nearest by the distance from the car's front bumper (its x, its lane's centre y) to
    the vehicle's centre, ties in order of appearance; x, y its centre, vx, vy its
    velocity, heading its direction of travel (0 along +x, counter-clockwise, in
    [-π, π]). Empty slots are zeros. ``V`` is 0 on a map without traffic rules (every
    straight-road map: the vector is the pedestrian layout alone) and 4 on one with them
    (the junction maps), unless ``vehicle_slots`` says otherwise.

    ## Rewards

    Per tick (the map's ``reward`` section): ``progress_per_metre`` × metres advanced
    (0.5), minus ``step_cost`` (4.5), plus ``goal`` (50) on arrival, plus ``crash`` (-25)
    on hitting a pedestrian. ``info["reward_terms"]`` gives the four terms.

    ## Episode End

    * ``terminated``: the car's front reached the destination, or it hit a pedestrian.
    * ``truncated``: ``episode.max_steps`` ticks (40) passed without either (a time-out).

    ## Info

    ``step`` (ticks done), ``collision``, ``goal``, ``timeout``, ``red_light`` (bools;
    ``red_light``: the car's front entered the crosswalk on red this tick), ``state`` (the
    true ``(d, v, L, p)``), ``observed`` (as observed), ``light`` (``"green"``,
    ``"amber"``, ``"red"``), ``light_code`` (0, 1, 2), ``light_time_left`` (s),
    ``reward_terms`` (``progress``, ``time``, ``goal``, ``crash``, ``red_light``).

    ## Seeding

    ``reset(seed=s)`` seeds ``self.np_random`` (Gymnasium) and draws from it one uint64,
    the key of the episode stream (:func:`episode_key`); the k-th episode since
    (``k = 0`` for this reset, then one more per ``reset()``) has world seed
    ``_unforeseen.stream_seed(key, k)`` (light offset, spawns, observation noise). So
    ``reset(seed=s)`` and the ``reset()`` calls after it are reproducible.
    ``reset(options={"world_seed": w})`` runs the episode with world seed ``w`` exactly
    (what ``unforeseen eval`` uses per episode: :func:`unforeseen.eval_seeds`).

    ## Arguments

    ``map``: an embedded map name (``unforeseen.embedded_maps()``) or a map file;
    ``observation``: ``"discrete"`` or ``"kinematic"``; ``render_mode``: see Rendering;
    ``render_scale``: pixels per metre of a frame (default 10);
    ``pedestrian_slots`` (kinematic, 1..=100, default 4); ``vehicle_slots`` (kinematic,
    0..=100; default ``None``: 4 on a map with traffic rules, 0 without); any other keyword overrides a map field
    (``max_steps=60``, ``lane_width=3.0``, ``reward__goal=40``; ``section__field`` when a
    name is in several sections; a name the optional ``junction`` shares with a section
    every map has means the latter's: ``junction__lane_width`` for the cross street's),
    checked by the map loader.

    ## Rendering

    ``render_mode="rgb_array"``: ``render()`` returns a top-down uint8 frame
    ``(height, width, 3)`` drawn in Rust (tiny-skia), about 1080x130 pixels for the
    shipped maps: grass, grey sidewalks, the road with its lane lines, the zebra
    crosswalk, the yellow destination line, the light (a disc on the near sidewalk, in
    its colour), the blue car (its windscreen lighter) and each pedestrian (a dark ring
    around orange on the crosswalk, magenta elsewhere). A map with a junction gives a
    taller frame (about 1080x510) that adds the cross street with its lanes, sidewalks,
    crosswalks and stop lines, every signal head (round for vehicles, square for
    pedestrians, grey while dark) and the other vehicles (teal, raspberry while in the
    car's path). ``"ansi"``: one line of text.
    ``"human"``: the frame in a pygame window, redrawn at each ``reset`` and ``step``
    at ``metadata["render_fps"]`` (one frame per decision tick: 1 per second by
    default); needs the ``render`` extra (``pip install "unforeseen[render]"``).
    ``gymnasium.wrappers.RecordVideo`` records ``rgb_array`` episodes to mp4 with the
    ``video`` extra (moviepy).
    """

    metadata = {"render_modes": ["rgb_array", "ansi", "human"], "render_fps": 1}

    def __init__(
        self,
        map: str = "jaywalk",
        observation: str = "discrete",
        render_mode: str | None = None,
        pedestrian_slots: int = 4,
        render_scale: float = 10.0,
        vehicle_slots: int | None = None,
        **map_overrides: Any,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode {render_mode!r}: expected None or one of {self.metadata['render_modes']}"
            )
        self._window: _Window | None = _Window() if render_mode == "human" else None
        self._env = _unforeseen.Env(map, observation, pedestrian_slots, map_overrides, vehicle_slots)
        self.render_mode = render_mode
        self._scale = float(render_scale)
        self.metadata = {**type(self).metadata, "render_fps": 1.0 / self._env.decision_dt}
        self.action_space = spaces.Discrete(3)
        if observation == "discrete":
            self.observation_space = spaces.MultiDiscrete(np.array(self._env.factor_sizes, dtype=np.int64))
        else:
            low, high = self._env.kinematic_bounds()
            self.observation_space = spaces.Box(low, high, dtype=np.float32)
        self._keyed = False

    @property
    def map_name(self) -> str:
        """The map's name."""
        return self._env.map_name

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if options and "world_seed" in options:
            out = self._env.reset(options["world_seed"])
        else:
            if seed is not None or not self._keyed:
                self._env.set_stream(episode_key(self.np_random))
                self._keyed = True
            out = self._env.reset_next()
        if self._window is not None:
            self._window.show(self._env.render_rgb(self._scale), self.metadata["render_fps"])
        return out

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        out = self._env.step(action)
        if self._window is not None:
            self._window.show(self._env.render_rgb(self._scale), self.metadata["render_fps"])
        return out

    def render(self) -> np.ndarray | str | None:
        if self.render_mode == "rgb_array":
            return self._env.render_rgb(self._scale)
        if self.render_mode == "ansi":
            return self._env.render_ansi()
        return None  # "human" draws at each reset and step, as Gymnasium's envs do

    def close(self) -> None:
        if self._window is not None:
            self._window.close()
        super().close()

    def kinematic(self) -> np.ndarray:
        """The kinematic vector now, whatever the observation form."""
        return self._env.kinematic()


class _Window:
    """The pygame window of ``render_mode="human"``."""

    def __init__(self) -> None:
        try:
            import pygame
        except ImportError as e:
            raise gym.error.DependencyNotInstalled(
                'render_mode="human" needs pygame, which the render extra installs: '
                'pip install "unforeseen[render]" (or pip install pygame)'
            ) from e
        self._pygame = pygame
        self._screen: Any = None
        self._clock = pygame.time.Clock()

    def show(self, frame: np.ndarray, fps: float) -> None:
        pg = self._pygame
        h, w, _ = frame.shape
        if self._screen is None:
            # The display alone: pygame.init() would open the audio device too, which a
            # headless machine reports line by line on stderr (ALSA), and the env has no sound.
            pg.display.init()
            pg.display.set_caption("unforeseen")
            self._screen = pg.display.set_mode((w, h))
        pg.event.pump()
        self._screen.blit(pg.surfarray.make_surface(frame.swapaxes(0, 1)), (0, 0))
        pg.display.flip()
        self._clock.tick(fps)

    def close(self) -> None:
        if self._screen is not None:
            self._pygame.display.quit()
            self._pygame.quit()
            self._screen = None
