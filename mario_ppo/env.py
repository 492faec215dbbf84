"""Super Mario Bros on the real NES emulator (nes-py 9 / gym-super-mario-bros 9), wrapped as article 001.

Stack, innermost first::

    SuperMarioBros-<world>-<stage>-v0        the emulator, one NES frame per step
    JoypadSpace(SIMPLE_MOVEMENT | ...)       discrete button combinations
    Restarts                                 training only: start some episodes where an earlier one
                                             passed an x (off by default, mario_ppo/restarts.py)
    ClassicReward                            the reward gym-super-mario-bros had before 9.x
                                             (+ game score x score_reward, off by default)
    ArticleShaping                           +50 flag / -50 other ends, then / 10
    SkipAndStack(4) | SkipAndHistory(4)      one action for 4 frames; as channels, gray 84x84 frames:
                                             the step's 4 (article 001) or one per step for the
                                             last 4 steps (uvipen's), ``frames="history"``
    KilledBy                                 at a death, what killed Mario: a fall, the clock or
                                             the nearest enemy (``info["killed_by"]``,
                                             mario_ppo/deaths.py)
    DeadEnds                                 a known dead end of the level ends as a death (off by
                                             default; mario_ppo/episode_ends.py)
    StallLimit(n)                            truncate once x has not passed its best for n agent
                                             steps (off by default; mario_ppo/episode_ends.py)

Observations are ``uint8 [84, 84, 4]``; the model scales them to [0, 1] itself. Auto-reset is the
env pool's job (Gymnasium vector envs reset an env the step its episode ends).

The rewards (ClassicReward, ArticleShaping) are in mario_ppo/rewards.py.

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

import gymnasium as gym
import numpy as np

from mario_ppo.deaths import KilledBy
from mario_ppo.episode_ends import DeadEnds, StallLimit
from mario_ppo.levels import STAGE, WORLD
from mario_ppo.restarts import Restarts
from mario_ppo.rewards import ArticleShaping, ClassicReward

ACTION_SETS = ("simple", "complex", "right_only")
FRAME_STACKS = ("skipped", "history")
FRAME_SIZE = 84
INFO_KEYS = ("x_pos", "flag_get", "time", "world", "stage", "restarted", "start_x")  # what the wrappers pass on


def action_list(name: str) -> list:
    from gym_super_mario_bros import actions

    table = {"simple": actions.SIMPLE_MOVEMENT, "complex": actions.COMPLEX_MOVEMENT,
             "right_only": actions.RIGHT_ONLY}
    if name not in table:
        from rlcore.errors import UserError
        raise UserError(f"unknown action set {name!r}; choose one of {', '.join(ACTION_SETS)}")
    return table[name]


def gray_84(frame: np.ndarray) -> np.ndarray:
    """RGB NES frame (240x256x3) -> gray uint8 84x84 (the article's cv2 gray + resize).

    nes-py hands out its screen as a zero-copy RGB view of the emulator's 32-bit BGRx pixels
    (strides ``(1024, 4, -1)``). cv2 would first copy that view into a contiguous RGB image, which
    cost 0.64 ms a frame here; reading the same bytes as contiguous BGRA takes 0.07 ms and gives
    the same gray image, bit for bit (the same weights on the same channels).
    """
    import cv2  # the mario extra (imported here, so `main.py list` works without it)

    if frame.ndim == 3 and frame.strides[1:] == (4, -1):
        bgrx = np.lib.stride_tricks.as_strided(frame[:, :, ::-1], (*frame.shape[:2], 4),
                                               (frame.strides[0], 4, 1), writeable=False)
        gray = cv2.cvtColor(bgrx, cv2.COLOR_BGRA2GRAY)
    else:
        gray = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY)
    return cv2.resize(gray, (FRAME_SIZE, FRAME_SIZE))


class SkipAndStack(gym.Wrapper):
    """Repeat each action for ``skip`` frames; observe those frames (gray 84x84) as channels.

    Rewards of the skipped frames are summed. If the episode ends early, the last frame fills the
    remaining channels. Reset shows the first frame ``skip`` times, or for a restart (below) the last
    ``skip`` frames it played in (``info["warmup_frames"]``). ``info`` is trimmed to
    :data:`INFO_KEYS` (less to send over the pool's Pipes). With ``render_mode="rgb_array"``, every
    emulator frame of the last step is kept in ``self.frames`` for a full-rate video.
    """

    def __init__(self, env: gym.Env, skip: int = 4):
        super().__init__(env)
        self.skip = skip
        self.observation_space = gym.spaces.Box(0, 255, (FRAME_SIZE, FRAME_SIZE, skip), np.uint8)
        self.frames: list[np.ndarray] = []

    def _keep(self, frame):
        if self.env.render_mode == "rgb_array":
            self.frames.append(frame)

    def reset(self, *, seed=None, options=None):
        frame, info = self.env.reset(seed=seed, options=options)
        self.frames = []
        self._keep(frame)
        return self._first_obs(frame, info.get("warmup_frames", [])), _trim(info)

    def _first_obs(self, frame, warmup: list) -> np.ndarray:
        """The 4 frames of the step that ended in ``frame``: the last frames of ``warmup``, else
        ``frame`` repeated."""
        grays = [gray_84(f) for f in warmup[-self.skip:]] or [gray_84(frame)]
        return np.stack([grays[0]] * (self.skip - len(grays)) + grays, axis=2)

    def step(self, action):
        obs = np.empty((FRAME_SIZE, FRAME_SIZE, self.skip), np.uint8)
        total, terminated, truncated = 0.0, False, False
        self.frames = []
        for i in range(self.skip):
            frame, reward, terminated, truncated, info = self.env.step(action)
            self._keep(frame)
            total += reward
            obs[:, :, i] = gray_84(frame)
            if terminated or truncated:
                obs[:, :, i + 1:] = obs[:, :, i:i + 1]
                break
        return obs, total, terminated, truncated, _trim(info)


class SkipAndHistory(SkipAndStack):
    """Repeat each action for ``skip`` frames; observe the last ``skip`` agent steps, one channel each:
    the pixel-wise max of the gray frames of the step's second half (uvipen's PyTorch original).

    The max keeps sprites that the NES draws on alternate frames. The stack spans 4 agent steps (16
    frames) instead of one: a Mario standing still for several steps (against a pipe, holding A,
    which does not jump again until released) looks different from one that has just landed, so a
    policy can act differently in the two. Only the pooled half of each step is converted to gray.
    If the episode ends before the pooled half, the last frame is the step's channel. Reset shows
    the first frame ``skip`` times, or for a restart the steps it played in (``info["warmup_frames"]``,
    cut into steps of ``skip`` frames that end at its last frame).
    """

    def reset(self, *, seed=None, options=None):
        self._stack, info = super().reset(seed=seed, options=options)
        return self._stack, info

    def _first_obs(self, frame, warmup: list) -> np.ndarray:
        steps = [warmup[max(0, end - self.skip):end] for end in range(len(warmup), 0, -self.skip)][::-1]
        pooled = [np.max([gray_84(f) for f in step[self.skip // 2:] or step[-1:]], axis=0)
                  for step in steps[-self.skip:]]
        if not pooled:
            pooled = [gray_84(frame)]
        return np.stack([pooled[0]] * (self.skip - len(pooled)) + pooled, axis=2)

    def step(self, action):
        total, terminated, truncated = 0.0, False, False
        self.frames, pooled = [], []
        for i in range(self.skip):
            frame, reward, terminated, truncated, info = self.env.step(action)
            self._keep(frame)
            total += reward
            if i >= self.skip // 2:
                pooled.append(gray_84(frame))
            if terminated or truncated:
                break
        newest = np.max(pooled, axis=0) if pooled else gray_84(frame)
        # a new array each step (never written in place), so a returned observation stays as it was
        self._stack = np.concatenate([self._stack[:, :, 1:], newest[:, :, None]], axis=2)
        return self._stack, total, terminated, truncated, _trim(info)


def _trim(info: dict) -> dict:
    return {k: info[k] for k in INFO_KEYS if k in info}


def make_env(render_mode: str | None = None, max_episode_steps: int | None = None, world: int = 1,
             stage: int = 1, actions: str = "simple", skip: int = 4, score_reward: float = 0.0,
             stall_steps: int = 0, stall_outcome: str = "truncate", frames: str = "skipped",
             dead_ends: bool = False, restart_x: int = 0, restart_every: int = 0,
             restart_share: float = 0.0, restart_weights: str = "uniform",
             restart_keep: str = "latest", restart_back_step: int = 0, restart_goal_x: int = 0,
             restart_back_share: float = 0.5) -> gym.Env:
    """The article's Mario env for one stage. ``max_episode_steps`` counts agent steps (None = none);
    ``score_reward``: reward per game-score point (0 = the article's reward); ``stall_steps``: end
    an episode after this many agent steps without a new best x (0 = never), as a truncation or as a
    death (``stall_outcome``); ``frames``: the 4 channels hold the 4 frames of this step ("skipped") or
    the last 4 steps ("history", see :class:`SkipAndHistory`); ``dead_ends``: end an episode as a death
    in a known dead end of the level (:data:`DEAD_ENDS`); ``restart_x`` or ``restart_every``,
    ``restart_share``: start that share of episodes where an earlier one passed that x or a multiple
    of that spacing, the point drawn by ``restart_weights``, each point's state kept by ``restart_keep``,
    the x stepped back by ``restart_back_step`` once ``restart_back_share`` of the restarts get past
    ``restart_goal_x`` (training only, :mod:`mario_ppo.restarts`)."""
    from rlcore.host.extras import require

    for module in ("cv2", "nes_py", "gym_super_mario_bros"):  # the mario extra, or one line
        require(module, "Mario")
    import gym_super_mario_bros  # noqa: F401  registers the SuperMarioBros-* ids
    from nes_py.wrappers import JoypadSpace

    from rlcore.errors import UserError

    if not (WORLD.accepts(world) and STAGE.accepts(stage)):
        raise UserError(f"there is no level {world}-{stage}: world is {WORLD.describe()}, "
                        f"stage {STAGE.describe()}")
    if frames not in FRAME_STACKS:
        raise UserError(f"unknown frame stack {frames!r}; choose one of {', '.join(FRAME_STACKS)}")
    env = gym.make(f"SuperMarioBros-{world}-{stage}-v0", render_mode=render_mode).unwrapped
    env = JoypadSpace(env, action_list(actions))
    if (restart_x or restart_every) and restart_share:
        env = Restarts(env, restart_share, x=restart_x, every=restart_every, weights=restart_weights,
                       keep=restart_keep, back_step=restart_back_step, goal_x=restart_goal_x,
                       back_share=restart_back_share)
    stack = SkipAndHistory if frames == "history" else SkipAndStack
    env = KilledBy(stack(ArticleShaping(ClassicReward(env, score_reward)), skip))
    if dead_ends:
        env = DeadEnds(env, world, stage)
    if stall_steps:
        env = StallLimit(env, stall_steps, stall_outcome)
    if max_episode_steps:
        env = gym.wrappers.TimeLimit(env, max_episode_steps)
    return env
