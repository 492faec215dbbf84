"""Stand-in emulators for the Mario wrappers' rules: they replay scripted infos (and RAM)."""
import gymnasium as gym
import numpy as np


class ScriptedInfos(gym.Env):
    """A stand-in emulator that replays a list of infos (x, clock, score, dying)."""
    observation_space, action_space = gym.spaces.Discrete(1), gym.spaces.Discrete(1)

    def __init__(self, infos):
        self.infos = [dict(x_pos=x, time=t, score=sc, is_dying=d, is_dead=False) for x, t, sc, d in infos]

    def reset(self, *, seed=None, options=None):
        self.i = 0
        return 0, self.infos[0]

    def step(self, action):
        self.i += 1
        return 0, 123.0, False, False, self.infos[self.i]


class ScriptedPlaces(ScriptedInfos):
    """The stand-in with an area type in RAM 0x074E, as the emulator keeps it."""

    def __init__(self, places):
        super().__init__([(x, 400, 0, False) for x, _ in places])
        self.areas = [area for _, area in places]
        self.ram = np.zeros(2048, np.uint8)

    def step(self, action):
        out = super().step(action)
        self.ram[0x074E] = self.areas[self.i]
        return out
