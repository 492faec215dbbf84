"""The Mario presets: `levels` is the default plus the recipe the shipped 1-4 model was trained with."""
import dataclasses
import json

from mario_ppo.experiment import EXPERIMENT
from tests.test_cli import ROOT


def test_the_levels_preset_is_the_default_plus_the_shipped_1_4_recipe():
    default, levels = EXPERIMENT.preset("ppo", "default"), EXPERIMENT.preset("ppo", "levels")
    changed = {f.name for f in dataclasses.fields(default) if getattr(default, f.name) != getattr(levels, f.name)}
    assert changed == {"frames", "score_reward", "value_loss", "target_kl", "stall_steps", "stall_outcome"}
    trained = json.loads((ROOT / "saved_networks" / "mario_ppo" / "1-4" / "meta.json").read_text())["config"]
    # everything but the stall length (40, from 2-1's run; 1-4 had 80) as 1-4 recorded it
    assert {name: trained[name] for name in changed - {"stall_steps"}} == {
        name: getattr(levels, name) for name in changed - {"stall_steps"}}
    assert (trained["stall_steps"], levels.stall_steps) == (80, 40)
    assert (levels.world, levels.stage, levels.entropy_coef) == (1, 1, default.entropy_coef)
