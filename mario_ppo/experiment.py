"""Super Mario Bros with PPO (article 001): presets and registration. TensorFlow-free.

The level and action set are hyperparameters (``--world 1 --stage 1 --actions simple``), so
they are recorded in every checkpoint and ``meta.json`` and a saved model rebuilds its own env.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from mario_ppo.curriculum import lend_routes
from mario_ppo.deaths import cause_name
from mario_ppo.env import ACTION_SETS, FRAME_STACKS, make_env
from mario_ppo.episode_ends import StallLimit
from mario_ppo.levels import STAGE, WORLD
from mario_ppo.restarts import KEEPS, WEIGHTS
from rlcore.algorithms.ppo.config import PPOConfig
from rlcore.environments.experiment import AlgoSpec, Bar, Curriculum, Experiment, Goal, SeedsBar, ShippedBy
from rlcore.host import extras
from rlcore.hyperparams.allowed import OFF_OR_COUNT, Allowed, choices, flag, require


@dataclass(frozen=True)
class MarioPPOConfig(PPOConfig):
    world: int = field(default=1, metadata={"help": "world", "allowed": WORLD})
    stage: int = field(default=1, metadata={"help": "stage", "allowed": STAGE})
    actions: str = field(default="simple", metadata={"help": "button set: 7, 12 or 5 actions",
                                                     "allowed": choices(*ACTION_SETS)})
    score_reward: float = field(default=0.0, metadata={
        "help": "reward per game-score point, added before the /10 (uvipen's PyTorch original: "
                "1/40 = 0.025; 0 = the article's reward)", "allowed": Allowed(low=0, high=1)})
    stall_steps: int = field(default=0, metadata={
        "help": "end an episode (truncated, bootstrapped) after this many agent steps without a new "
                "best x (0 = never)", "allowed": OFF_OR_COUNT})
    frames: str = field(default="skipped", metadata={
        "help": "what the 4 input channels hold: skipped = the 4 frames of this step (article 001); "
                "history = the last 4 steps, each the max of its last 2 frames (uvipen's PyTorch "
                "original), so standing still against a wall is visible", "allowed": choices(*FRAME_STACKS)})
    dead_ends: bool = field(default=False, metadata={
        "help": "end an episode as a death where the level has a known dead end for these buttons "
                "(1-2: the ceiling route into the warp zone); the flags counted do not change"})
    stall_outcome: str = field(default="truncate", metadata={
        "help": "how a stall ends: truncate (bootstrapped from V) or death (terminated, -50 / 10, "
                "as the clock would end it)", "allowed": choices(*StallLimit.OUTCOMES)})
    restart_x: int = field(default=0, metadata={
        "help": "training only: start a share (--restart-share) of episodes from the state in which an "
                "earlier episode first passed this x, to practise a hard place far into the level; "
                "evaluation always starts at the level's start (0 = off)", "allowed": OFF_OR_COUNT})
    restart_every: int = field(default=0, metadata={
        "help": "training only: as --restart-x, at every multiple of this x that an earlier episode "
                "passed, the point drawn uniformly for each restarted episode, for a level whose hard "
                "places are not known (0 = off)", "allowed": OFF_OR_COUNT})
    restart_share: float = field(default=0.5, metadata={
        "help": "with --restart-x or --restart-every: the share of training episodes that start there; "
                "they are left out of the flag share the stop rule reads", "allowed": Allowed(low=0, high=1)})
    restart_weights: str = field(default="uniform", metadata={
        "help": "with --restart-every: how a restarted episode's point is drawn: uniform, or deaths (in "
                "proportion to 1 + the env's recent failed episodes that ended between that point and "
                "the next, so the places where the policy dies get the most tries)",
        "allowed": choices(*WEIGHTS)})
    restart_keep: str = field(default="latest", metadata={
        "help": "with --restart-x or --restart-every: which state a point keeps: latest (of the last "
                "episode that passed it, so the points follow the policy), or furthest (of the episode "
                "that went furthest past it, so the points before a gap hold a crossing's takeoff even "
                "after the policy has stopped crossing)", "allowed": choices(*KEEPS)})
    restart_back_step: int = field(default=0, metadata={
        "help": "with --restart-x: step each env's restart x back by this many x whenever its restarted "
                "episodes got past --restart-goal-x in at least --restart-back-share of its last 40, "
                "and forward again (never past --restart-x) when at most 10 %% did: a backward "
                "curriculum by rule (0 = off: the x stays)", "allowed": OFF_OR_COUNT})
    restart_goal_x: int = field(default=0, metadata={
        "help": "with --restart-back-step: the x past which a restarted episode counts as a success "
                "(past the hard place, e.g. 850 on 1-3)", "allowed": OFF_OR_COUNT})
    restart_back_share: float = field(default=0.5, metadata={
        "help": "with --restart-back-step: the share of an env's last 40 restarted episodes that must "
                "get past --restart-goal-x before its x steps back",
        "allowed": Allowed(low=0, high=1, low_open=True)})

    # `train mario_ppo ppo --help` lists these apart from PPO's own hyperparameters
    HELP_GROUPS = {
        "the level and its env (each defines the run: a resume cannot change it)":
            ("world", "stage", "actions", "frames", "score_reward", "stall_steps", "stall_outcome", "dead_ends"),
        "restarts, a training curriculum (research knobs, off by default; evaluation always starts at the "
        "level's start)":
            ("restart_x", "restart_every", "restart_share", "restart_weights", "restart_keep",
             "restart_back_step", "restart_goal_x", "restart_back_share"),
    }

    def __post_init__(self):
        super().__post_init__()
        require(not (self.restart_x and self.restart_every),
                f"{flag('restart_x')} and {flag('restart_every')} are two ways to say where restarts start: give one")
        require(not self.restart_back_step or self.restart_goal_x > self.restart_x > 0,
                f"{flag('restart_back_step')} needs {flag('restart_x')} and a {flag('restart_goal_x')} past it")

    def inert_fields(self) -> dict[str, str]:
        inert = super().inert_fields()
        if not (self.restart_x or self.restart_every):
            inert.update(dict.fromkeys(("restart_share", "restart_keep", "restart_weights"),
                                       f"there is no restart point; add {flag('restart_x')} or {flag('restart_every')}"))
        elif not self.restart_every:
            inert["restart_weights"] = (f"it weighs the points of {flag('restart_every')}, and "
                                        f"{flag('restart_x')} gives a single point")
        if not self.restart_back_step:
            inert.update(dict.fromkeys(("restart_goal_x", "restart_back_share"),
                                       f"it tunes {flag('restart_back_step')}, which is off"))
        return inert


# Article 001: 8 envs x 512 steps, GAE gamma 0.99 lambda 0.97, clip 0.2, entropy 0.05, Adam 1e-4,
# 10 epochs of minibatch 256, value loss added unweighted, TD(0) value target, its ratio and
# entropy approximations, 200 rollouts, a checkpoint every 10.
ARTICLE = MarioPPOConfig(
    value_target="td0", article_quirks=True, max_env_steps=200 * 512 * 8, max_episodes=10**9,
    max_episode_steps=0, stop_score=1e9, window=100)
# Default: the same numbers with the quirks fixed (log-ratio, true entropy, lambda-return value
# target), gradients clipped at norm 0.5, a 6M-step budget, and a stop once 80 % of the last 100
# training episodes reached the flag. Why 80 %: training episodes sample from pi exactly as the
# 10-episode evaluation does, so the evaluation's flag count is about Binomial(10, share). At 0.5
# (the first shipped 1-1 run) that meets the 5-of-10 bar only 62 % of the time, and that run got 3;
# at 0.8 it is 99 %. 1-1's bar of 8 of 10 wants more: at 0.9 it is 93 % (`--stop-success-share 0.9`).
# The entropy weight is 0.01, not 0.05: the article's "entropy",
# the mean of -log p(a) over actions drawn from the old policy, has zero expected gradient at the
# old policy (sum_a p(a) grad log p(a) = grad sum_a p(a) = 0), so it barely regularized; with a
# true entropy at 0.05 our 1-1 policy stayed at 1.0-1.3 nats (of ln 7 = 1.95) and reached the flag
# in about 1 % of its episodes over 70 rollouts. Gamma is 0.9 with lambda 1.0 (Monte-Carlo
# advantages over a short 10-step horizon): with the article's 0.99 / 0.97 our 1-1 run stalled at
# x ~2,300 for 70 rollouts and saw no flag after rollout 93, while the same seed at 0.9 / 1.0 was
# ahead in mean x in all 8 blocks of 10 rollouts up to rollout 80 and reached the flag in 41 % of
# its last 100 training episodes by rollout 123.
DEFAULT = dataclasses.replace(
    ARTICLE, value_target="gae", article_quirks=False, max_grad_norm=0.5, max_env_steps=6_000_000,
    stop_success_share=0.8, entropy_coef=0.01, gamma=0.9, gae_lambda=1.0)

# Levels: the default plus the settings with which 1-4 reached its axe from random weights (and 2-1 its
# flag), for a level trained from scratch. Each was added for a failure seen on a level:
# - frames history: the 4 channels hold the last 4 steps (the PyTorch original's input), so Mario
#   standing still against a wall is visible; with the 4 skipped frames of one step it is not;
# - score reward 0.025: the original's reward for the game score (stomps, coins, the flag's height);
# - Huber value loss and a KL guard of 0.2: 1-2's policy collapsed in one update (approx KL 0.28
#   against 0.02-0.04 before) with the squared error and no guard;
# - a stall of 40 steps ends the episode as a death: 1-2 sat at a ledge and 2-1 pushed at a wall until
#   the clock; at gamma 0.9 a penalty 80 steps away is worth 0.9^80 x -5, nothing, so 2-1 went from 80
#   to 40 steps (restarted episodes over its wall: 5.7 % -> 9.8 %). 1-4 trained with 80.
# 1-4 and 2-1 also lowered the entropy weight to 0.003 once the flag came now and then; the preset leaves
# that to a resume (`--entropy-coef 0.003`), since early on 0.01 keeps the policy trying.
# 2-1 also needed its learning rate halved twice (at flag shares of ~35 % and ~45 %) before it passed
# 36 %; `--lr-halve-at 0.3,0.45` does that by rule. It is not in the preset until a level has shown it,
# so the commands of the levels already shipped still mean what they meant.
LEVELS = dataclasses.replace(
    DEFAULT, frames="history", score_reward=0.025, value_loss="huber", target_kl=0.2, stall_steps=40,
    stall_outcome="death")

# Flag (issue 63): one recipe for all eight levels, fixed on 2026-12-03 before any of its runs, so that
# `train mario_ppo ppo --preset flag --world W --stage S` is each level's whole command: the levels
# preset, plus by rule what the hand-steered runs of 1-2 ... 2-4 did by hand between resumes:
# - restarts at every multiple of 300 x an earlier episode passed, drawn in proportion to the deaths
#   after each point, for half the episodes (1-3, 2-2, 2-3 and 2-4 crossed their hard places this way;
#   restarted episodes are left out of the stop rule's share);
# - the learning rate halved at flag shares 0.3, 0.5, 0.7 (2-1: 1e-4 -> 1.25e-5 by hand, 2-2 the same);
# - the entropy weight halved at 0.1, 0.3, 0.5, 0.7 (by hand: 0.01 -> 0.003 -> 0.001 -> 0 on 2-1, 2-2,
#   2-3), so a policy sampled from pi stops pressing other buttons where one wrong press kills;
# - stop at a 0.95 flag share over the last 100 episodes from the level's start, for the bar of 27 of
#   30 unseen-seed episodes (the 1-1 seeds stopped at 0.9 scored 23, 26 and 24 of 30); a 10M budget.
FLAG = dataclasses.replace(
    LEVELS, restart_every=300, restart_weights="deaths", restart_share=0.5, lr_halve_at=(0.3, 0.5, 0.7),
    entropy_halve_at=(0.1, 0.3, 0.5, 0.7), stop_success_share=0.95, max_env_steps=10_000_000)

LEVEL_NAMES = ("1-1", "1-2", "1-3", "1-4", "2-1", "2-2", "2-3", "2-4")  # the levels article 001 tried
# what others published per level: article 001 (its last section: every level but 1-3 reached the end) and the
# Stable-Baselines3 Mario models published with 100-episode evaluations (SPEC.md, issue 63)
SB3 = {"1-1": "100 %", "1-2": "97-100 %", "1-4": "97-100 %", "2-1": "82 %", "2-3": "98 %"}
PUBLISHED = {level: f"article 001: {'no' if level == '1-3' else 'yes'}; SB3: "
                    + (f"{SB3[level]} of 100" if level in SB3 else "none") for level in LEVEL_NAMES}

EXPERIMENT = Experiment(
    name="mario_ppo",
    description="Super Mario Bros (NES emulator, 84x84x4 gray frames, 7/12/5 actions), article 001",
    make_env=make_env,
    solved_score=None,  # success is the flag, not a return
    algos={"ppo": AlgoSpec("ppo", "ppo", "PPO, 8 envs over Pipes", {"article": ARTICLE, "default": DEFAULT,
                                                                   "levels": LEVELS, "flag": FLAG})},
    video_fps=60,
    env_fields=("world", "stage", "actions", "score_reward", "stall_steps", "stall_outcome",
                "frames", "dead_ends"),
    # issue 63: the level of the Mario models people can download (PUBLISHED), judged on 30 episodes, where 10
    # could not tell a share of 44 % from one of 97 %
    bars={level: Bar("success_share", 0.9, published=PUBLISHED[level], reason=
                     "the Mario models people can download reach the flag in 82-100 % of episodes (article 001 "
                     "reached it on every level from 1-1 to 2-4 but 1-3); we ask it in at least 27 of 30 "
                     "unseen-seed episodes on every level",
                     over_seeds=SeedsBar("median", 0.8, 3, "1-1's recipe from one command (issue 49): the flag in "
                                                           "80 % of episodes on the median of its seeds, and in 50 % "
                                                           "on every seed", least=0.5)
                     if level == "1-1" else None) for level in LEVEL_NAMES},
    below_bar={level: "trained before the bar of 27 of 30 was set (2026-12-07), by resumes steered by hand; it ships "
                      "until the level's run from one command (`long_runs/`, issue 63) replaces it"
               for level in ("1-1", "1-2", "1-4", "2-1", "2-2", "2-3", "2-4")},
    info_keys=("stalled", "start_x", "killed_by"),
    eval_episodes=30, score_label="return (shaped, /10)",
    # the flag is the goal; x_pos how far Mario got; killed_by what ended a failed episode
    goal=Goal(success_key="flag_get", progress_key="x_pos", cause_key="killed_by", cause_name=cause_name),
    # restarts (training only): restarted episodes start at start_x; the routes to each kept restart
    # point are kept by checkpoints and lent between envs on resume
    curriculum=Curriculum(
        env_fields=("restart_x", "restart_every", "restart_share", "restart_weights", "restart_keep",
                    "restart_back_step", "restart_goal_x", "restart_back_share"),
        partial_key="restarted", partial_start_key="start_x",
        memory="restart_routes", share_memory=lend_routes),
    shipped_by=ShippedBy(fields=("world", "stage"), default="1-1", noun="level"),  # saved_networks/mario_ppo/1-1
)

extras.declare("mario_ppo", "Mario", "mario", ("cv2", "nes_py", "gym_super_mario_bros"))  # checked early
