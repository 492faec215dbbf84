"""What killed Mario (mario_ppo/deaths.py): decoded from hand-set RAM, and on the real emulator."""
import math

import gymnasium as gym
import numpy as np

from mario_ppo.deaths import DYING, FELL, NEAR, NONE_NEAR, TIME_UP, KilledBy, cause_name, killed_by
from mario_ppo.env import make_env

RIGHT = 1  # SIMPLE_MOVEMENT


def dying_ram(mario=(2, 0x40, 120), clock=(3, 5, 0)) -> np.ndarray:
    """RAM of a small Mario dying on screen at (page, x, y), the clock at 350."""
    ram = np.zeros(2048, np.uint8)
    ram[0x0E], ram[0xB5] = DYING, 1
    ram[0x6D], ram[0x86], ram[0xCE] = mario
    ram[0x07F8:0x07FB] = clock
    return ram


def put_enemy(ram, slot, enemy_id, page, x, y):
    ram[0x0F + slot], ram[0x16 + slot] = 1, enemy_id
    ram[0x6E + slot], ram[0x87 + slot], ram[0xCF + slot] = page, x, y


def test_the_nearest_active_enemy_within_reach_is_the_killer():
    ram = dying_ram()
    put_enemy(ram, 0, 0x06, 2, 0x40 + 30, 120)        # a Goomba 30 px to the right
    put_enemy(ram, 3, 0x0A, 2, 0x40 - 8, 120 + 10)    # a grey Cheep-cheep 8 / 10 px away: nearer
    put_enemy(ram, 1, 0x07, 2, 0x40, 121)             # a Blooper on Mario, but not active:
    ram[0x0F + 1] = 0                                 # its slot's flag is off
    assert killed_by(ram) == 0x0A
    assert cause_name(killed_by(ram)) == "grey Cheep-cheep"


def test_the_page_counts_and_an_enemy_out_of_reach_is_no_one():
    ram = dying_ram(mario=(2, 0xFC, 120))
    put_enemy(ram, 0, 0x06, 3, 0x04, 120)              # 8 px to the right, across a page boundary
    assert killed_by(ram) == 0x06
    ram = dying_ram()
    put_enemy(ram, 0, 0x06, 2, 0x40 + NEAR + 1, 120)   # just beyond reach
    put_enemy(ram, 1, 0x06, 3, 0x40, 120)              # same x, one page (256 px) on
    assert killed_by(ram) == NONE_NEAR and cause_name(NONE_NEAR) == "no enemy near"


def test_a_fall_and_the_clock_come_before_any_enemy():
    ram = dying_ram()
    put_enemy(ram, 0, 0x06, 2, 0x40, 120)
    ram[0xB5] = 2                                      # below the screen: in a pit
    assert killed_by(ram) == FELL
    ram = dying_ram(clock=(0, 0, 0))
    put_enemy(ram, 0, 0x06, 2, 0x40, 120)
    assert killed_by(ram) == TIME_UP
    assert [cause_name(c) for c in (FELL, TIME_UP, 0x1B, 0x1F, 0x24, 0x28, 0x2C, 0x30)] == [
        "fell", "time up", "Firebar", "long Firebar", "a lift", "a lift", "a lift", "enemy 0x30"]


class _Ends(gym.Env):
    """A stand-in whose one step ends as scripted, with a dying Mario's RAM unless ``alive``."""
    observation_space, action_space = gym.spaces.Discrete(1), gym.spaces.Discrete(1)

    def __init__(self, terminated, flag=False, alive=False):
        self.terminated, self.flag = terminated, flag
        self.ram = dying_ram()
        put_enemy(self.ram, 0, 0x07, 2, 0x40, 110)
        if alive:
            self.ram[0x0E] = 0x08

    def reset(self, *, seed=None, options=None):
        return 0, {}

    def step(self, action):
        return 0, 0.0, self.terminated, not self.terminated, {"flag_get": self.flag}


def test_only_the_games_own_deaths_get_a_cause():
    def cause(**ends):
        env = KilledBy(_Ends(**ends))
        env.reset()
        return env.step(0)[4].get("killed_by")

    assert cause(terminated=True) == 0x07
    assert cause(terminated=True, flag=True) is None      # the flag
    assert cause(terminated=False) is None                # a truncation: a time limit, a stall
    assert cause(terminated=True, alive=True) is None     # a rule of ours that ends as a death


def test_on_the_emulator_running_right_on_1_1_meets_the_first_goomba():
    env = make_env(world=1, stage=1)
    env.reset(seed=0)
    try:
        for _ in range(200):
            _, _, terminated, truncated, info = env.step(RIGHT)
            if terminated or truncated:
                break
        assert terminated and not info["flag_get"]
        assert cause_name(info["killed_by"]) == "Goomba" and info["x_pos"] < 400
    finally:
        env.close()


def test_count_causes_counts_by_name_most_first():
    from rlcore.training.evaluation import count_causes

    records = [{"killed_by": c} for c in (0x0A, math.nan, 0x1B, 0x1C, FELL, 0x0A, 0x1D)] + [{"success": True}]
    assert count_causes(records, "killed_by", cause_name) == [("Firebar", 3), ("grey Cheep-cheep", 2),
                                                            ("fell", 1)]
    assert count_causes([{"success": True}], "killed_by", cause_name) == []
    # the stall limit ended it: no enemy's or fall's code, the episode's stalled mark
    stalls = [{"stalled": 1.0}, {"killed_by": FELL, "stalled": 0.0}, {"stalled": 1.0}]
    assert count_causes(stalls, "killed_by", cause_name) == [("stalled", 2), ("fell", 1)]
