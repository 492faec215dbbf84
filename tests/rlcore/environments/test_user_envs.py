"""Every env ``gym.make`` accepts trains (issue 65): ``render_mode`` goes only to an env asked for frames,
and only in a mode it declares; one that cannot render says so in one line."""
import pytest

from rlcore import api
from rlcore.errors import UserError

MODULE = "tests.user_envs_more"


@pytest.mark.parametrize("env_id", ["Bare-v0", "Own-v0", "Capped-v0", "Made-v0"])
def test_a_users_env_trains_and_evaluates_in_each_form(env_id, tmp_path):
    run = api.train(f"{MODULE}:{env_id}", "dqn", run_dir=tmp_path / "run", episodes=2, hidden=(8,),
                    final_eval_episodes=2, progress=False)
    lengths = {episode["length"] for episode in run.evaluation["per_episode"]}
    assert lengths == ({7} if env_id == "Capped-v0" else {10})  # the registered limit cuts the endless one
    assert api.evaluate(run, episodes=1)["episodes"] == 1


def test_the_registrations_own_kwargs_reach_the_class(tmp_path):
    run = api.train(f"{MODULE}:Own-v0", "dqn", run_dir=tmp_path / "run", episodes=1, hidden=(8,),
                    final_eval_episodes=0, progress=False)
    env = api.load(run).make_env()
    assert env.unwrapped.target == 0
    env.close()


def test_an_env_that_cannot_render_says_so_in_one_line(tmp_path):
    run = api.train(f"{MODULE}:Bare-v0", "dqn", run_dir=tmp_path / "bare", episodes=1, hidden=(8,),
                    final_eval_episodes=0, progress=False)
    with pytest.raises(UserError, match="Bare-v0 cannot render rgb_array frames: its env declares no render mode"):
        api.render(run, tmp_path / "bare.gif", episodes=1)
    assert not (tmp_path / "bare.gif").exists()
    own = api.train(f"{MODULE}:Own-v0", "dqn", run_dir=tmp_path / "own", episodes=1, hidden=(8,),
                    final_eval_episodes=0, progress=False)
    api.render(own, tmp_path / "own.gif", episodes=1)  # declares rgb_array: its frames are written
    assert (tmp_path / "own.gif").stat().st_size > 0
