"""A budget that ends an off-policy run before its first update gets a note before training: its model
would be the network it started with (`train Pendulum-v1 sac --steps 600`, learning_starts 10,000)."""
from rlcore.environments.registry import get_experiment
from rlcore.hyperparams.flags import apply_overrides
from rlcore.training.run import untrained_note


def test_a_budget_within_the_random_steps_is_noted_and_a_longer_one_is_not():
    sac = get_experiment("minitaur").preset("sac", None)
    note = untrained_note(apply_overrides(sac, {"max_env_steps": 600}))
    assert note == ("note: --max-env-steps 600 is no more than the 10,000 env steps the run collects before its "
                    "first update (--learning-starts 10,000): it will learn little or nothing")
    assert untrained_note(apply_overrides(sac, {"max_env_steps": 60_000})) is None
    dqn = get_experiment("lunar_lander").preset("dqn", None)
    assert untrained_note(dqn) is None  # no env-step budget: episodes end it
    assert untrained_note(get_experiment("cartpole").preset("a2c", None)) is None  # on-policy: updates at once
