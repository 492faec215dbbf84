"""What killed Mario: a fall, the clock, or the enemy nearest him, read from the NES RAM at his death.

The flag share says how often a level is cleared and x at the episode's end says where Mario died;
neither says by what. On 2-2 that mattered: x alone showed deaths spread over the whole water, the
RAM showed Cheep-cheeps at the water's surface. :class:`KilledBy` puts the cause in ``info`` as
``killed_by`` at every death the game itself brings (so metrics.csv and evaluation records carry
it), as one number:

- :data:`FELL` (-1): Mario below the screen, in a pit;
- :data:`TIME_UP` (-2): the clock at 0;
- the game's enemy id (0 and up, :data:`ENEMY_NAMES`) of the enemy object nearest Mario, if one
  is within :data:`NEAR` pixels on both axes;
- :data:`NONE_NEAR` (-3): none of these (a firebar's flames, for one, reach beyond their pivot).

Episodes that end otherwise (the flag, a stall, a dead end, a time limit) have no ``killed_by``:
NaN in the CSV. RAM addresses and enemy ids are those of the SMB disassembly (SMBDIS.ASM).

TensorFlow-free: env-pool worker processes import this module.
"""
from __future__ import annotations

import gymnasium as gym
import numpy as np

FELL, TIME_UP, NONE_NEAR = -1, -2, -3
NEAR = 48  # pixels: Mario and an enemy are 16 wide; a Blooper or Bowser's reach is more
ENEMY_SLOTS = 5

# RAM: Mario's page and x (0x6D, 0x86) and y on screen (0xCE); per enemy slot, from 0x0F (active
# flag), 0x16 (id), 0x6E (page), 0x87 (x), 0xCF (y); Mario's vertical screen (0xB5: 1 visible,
# > 1 below the screen), his state (0x0E: 0x0B dying, 0x06 dead), the clock's 3 digits (0x07F8)
DYING, DEAD = 0x0B, 0x06

ENEMY_NAMES = {
    0x00: "Green Koopa", 0x02: "Buzzy Beetle", 0x03: "Red Koopa", 0x05: "Hammer Bro", 0x06: "Goomba",
    0x07: "Blooper", 0x08: "Bullet Bill", 0x0A: "grey Cheep-cheep", 0x0B: "red Cheep-cheep",
    0x0C: "Podoboo", 0x0D: "Piranha Plant", 0x0E: "Green Paratroopa", 0x0F: "Red Paratroopa",
    0x10: "Green Paratroopa", 0x11: "Lakitu", 0x12: "Spiny", 0x14: "flying Cheep-cheep",
    0x15: "Bowser's flame", 0x1B: "Firebar", 0x1C: "Firebar", 0x1D: "Firebar", 0x1E: "Firebar",
    0x1F: "long Firebar", 0x2D: "Bowser", 0x33: "Bullet Bill",
    # the lifts are objects in the same slots: one nearest a death says where it came, not who dealt it
    **{code: "a lift" for code in range(0x24, 0x2D)},
}


def killed_by(ram: np.ndarray) -> int:
    """The cause of the death whose RAM this is (see the module docstring for the numbers)."""
    if ram[0xB5] > 1:
        return FELL
    if not ram[0x07F8:0x07FB].any():
        return TIME_UP
    mario_x, mario_y = int(ram[0x6D]) * 256 + int(ram[0x86]), int(ram[0xCE])
    nearest, nearest_id = NEAR + 1, NONE_NEAR
    for slot in range(ENEMY_SLOTS):
        if not ram[0x0F + slot]:
            continue
        x = int(ram[0x6E + slot]) * 256 + int(ram[0x87 + slot])
        distance = max(abs(x - mario_x), abs(int(ram[0xCF + slot]) - mario_y))
        if distance < nearest:
            nearest, nearest_id = distance, int(ram[0x16 + slot])
    return nearest_id


def is_game_death(ram: np.ndarray) -> bool:
    """Mario is dying or dead in the game (not the flag, not a rule of ours)."""
    return ram[0x0E] in (DYING, DEAD) or ram[0xB5] > 1


def cause_name(code: float) -> str:
    """A ``killed_by`` number in words."""
    code = int(code)
    return {FELL: "fell", TIME_UP: "time up", NONE_NEAR: "no enemy near"}.get(
        code, ENEMY_NAMES.get(code, f"enemy 0x{code:02X}"))


class KilledBy(gym.Wrapper):
    """Add ``info["killed_by"]`` (:func:`killed_by`) at each step that ends in a death of the game.

    Wraps the frame stack, which stops its frames at the first frame of a death, so the RAM read
    here is that frame's.
    """

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if terminated and not info.get("flag_get"):
            ram = self.env.unwrapped.ram
            if is_game_death(ram):
                info["killed_by"] = killed_by(ram)
        return obs, reward, terminated, truncated, info
