"""``main.py status``'s headline in words: what stopped a run, as the cards say it, and a short run's
wall time in seconds (a 393 s run read '0.1 h', a 122 s one '0.0 h')."""
from __future__ import annotations

from rlcore.environments.registry import get_experiment
from rlcore.records.status import headline


def test_a_finished_runs_headline_says_what_stopped_it_in_words():
    lander = {"experiment": "lunar_lander", "algo": "dqn", "preset": "default", "seed": 0, "env_steps": 475_111,
              "episodes": 1_030, "wall_seconds": 122.4, "stopped_by": "stop_eval_score 250.0", "config": {}}
    assert headline(lander, get_experiment("lunar_lander")) == (
        "lunar_lander dqn (default preset, seed 0): model at 475,111 env steps, 1,030 episodes, 122 s of training; "
        "stopped by a periodic evaluation of 250.0 or more")
    castle = {**lander, "experiment": "mario_ppo", "algo": "ppo", "wall_seconds": 11_331.0,
              "stopped_by": "stop_success_share 0.9", "config": {"world": 1, "stage": 4, "window": 100}}
    assert headline(castle, get_experiment("mario_ppo")).endswith(
        "3.1 h of training; stopped by the axe reached in 90% or more of the last 100 training episodes from the start")


def test_rollouts_of_a_task_without_a_success_event_give_no_success_share(tmp_path):
    """PPO on CartPole-v1 logs rollouts.csv too; its blocks said 'success 0/1024' of a goal it has none of."""
    from rlcore.environments.gym_experiment import gym_experiment
    from rlcore.records.status import rollout_lines

    rows = ["rollout,env_steps,episodes_ended,successes,entropy"] + [f"{r},{512 * r},{20 + r},0,0.6" for r in (1, 2)]
    (tmp_path / "rollouts.csv").write_text("\n".join(rows) + "\n")
    (line,) = rollout_lines(tmp_path / "rollouts.csv", gym_experiment("CartPole-v1"), block=2, blocks=1)
    assert line == "rollouts 1-2: 43 episodes ended | entropy 0.60"


def test_a_run_resumed_on_another_cpu_names_each_with_where_it_took_over():
    from rlcore.records.commands import cpus_text

    epyc, xeon = "AMD EPYC (avx2 avx512_bf16)", "Intel Xeon (avx2 avx512f)"
    starts = [{"env_steps": 0, "cpu": epyc}, {"env_steps": 286_720, "cpu": epyc}, {"env_steps": 614_400, "cpu": xeon}]
    assert cpus_text({"cpu": xeon, "command_starts": starts}) == f"{epyc}; {xeon} from 614,400 env steps"
    assert cpus_text({"cpu": epyc, "command_starts": starts[:2]}) == epyc  # one CPU throughout
    assert cpus_text({"cpu": xeon, "command_starts": [None, {"env_steps": 9}]}) == xeon  # older records: meta's
    assert cpus_text({}) is None
    # begun with code that recorded no CPU, resumed with code that does (Mario 1-1 seed 2): not passed off as
    # one CPU throughout
    mixed = [{"env_steps": 0}, {"env_steps": 614_400}, {"env_steps": 942_080, "cpu": xeon}]
    assert cpus_text({"cpu": xeon, "command_starts": mixed}) == f"not recorded; {xeon} from 942,080 env steps"


def test_the_hours_left_to_a_budget_say_a_stop_rule_may_end_the_run_sooner():
    """Mario 1-1's seeds run to a 0.9 flag share, under a 6M-step budget they never reach: the hours to that
    budget are an upper bound, and the line says so."""
    from pathlib import Path

    from rlcore.records.pace import Pace, pace_text

    measured = Pace(53.0, 25.5 * 3600, "6,000,000 env steps")
    text = pace_text(Path("unread.csv"), {"config": {"max_env_steps": 6_000_000, "stop_success_share": 0.9}}, measured)
    assert text == ("53 env steps/s lately, about 25.5 h to its budget of 6,000,000 env steps "
                    "(its stop rule may end it sooner)")
    assert pace_text(Path("unread.csv"), {"config": {"max_env_steps": 6_000_000}}, measured).endswith("env steps")
