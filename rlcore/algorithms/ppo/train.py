"""Rollout loop for PPO over the env pool: ``n_steps`` x ``num_envs`` transitions, then one update.

Experiments may name an info key that marks success (Mario: ``flag_get``) and one that measures
progress (Mario: ``x_pos``); the trainer then logs the success of every episode, the share over
the last ``window`` episodes, and prints one line per rollout with the max and min progress (the
article's console line; :class:`RolloutLog`).
"""
from __future__ import annotations

import time
from pathlib import Path

import keras
import numpy as np
from tqdm.auto import tqdm  # a widget in a notebook, text in a terminal

from rlcore.algorithms.ppo.agent import MODEL_FILE, UPDATE_NAMES, PPOAgent
from rlcore.algorithms.ppo.halving import HalvingAtShares, LearningRateHalving
from rlcore.algorithms.ppo.rollout_log import RolloutLog
from rlcore.environments.vector import EnvPool
from rlcore.errors import UserError
from rlcore.host.cpu import bfloat16_note, cpu_flags
from rlcore.hyperparams.allowed import flag
from rlcore.training import checkpoints
from rlcore.training.divergence import reported_divergence
from rlcore.training.session import TrainingSession
from rlcore.training.spec import RunSpec


class Rollout:
    """Preallocated [T, N] buffers of one rollout (frames stay uint8).

    A truncated episode is bootstrapped from V of its final observation, as in A2C; only the bookkeeping
    differs. A2C (:mod:`rlcore.algorithms.a2c.train`) keeps every step's next observation and values them all in
    its update; for Mario's frames that second [T, N] observation buffer would be 8 x 512 x 84 x 84 x 4
    bytes, 116 MB more, so PPO keeps V of each next state as it collects (the next step's value) and
    values only the final observations of the truncated episodes, in one batched call per step.
    """

    def __init__(self, t: int, n: int, obs_shape: tuple, obs_dtype=np.uint8):
        self.obs = np.zeros((t, n, *obs_shape), obs_dtype)
        self.actions = np.zeros((t, n), np.int32)
        (self.logp, self.values, self.next_values, self.rewards, self.terminated,
         self.dones) = (np.zeros((t, n), np.float32) for _ in range(6))

    def close(self, last_values: np.ndarray, truncated_values: dict) -> None:
        """next_values[t] = values[t + 1]; the last row from ``last_values``; truncated steps from
        the value of their final observation (``truncated_values[(t, i)]``)."""
        self.next_values[:-1] = self.values[1:]
        self.next_values[-1] = last_values
        for (t, i), v in truncated_values.items():
            self.next_values[t, i] = v

    def arrays(self):
        return (self.obs, self.actions, self.logp, self.values, self.next_values, self.rewards,
                self.terminated, self.dones)


def train(spec: RunSpec) -> Path:
    """Rollouts and updates until the session says stop; the model folder at the end."""
    keras.utils.set_random_seed(spec.seed)
    envs = EnvPool([spec.experiment.training_env_factory(spec.config)] * spec.config.num_envs, mode=spec.config.vec)
    with envs.closed_on_error():  # a start that fails (a wrong --init-from model, say) ends them quietly
        run = RolloutLoop(spec, envs)
    with envs, run.session.interruptible():
        while not run.session.should_stop():
            log, collect_seconds = run.collect()
            losses, update_seconds = run.learn()
            run.report(log, losses, {"collect_seconds": collect_seconds, "update_seconds": update_seconds})
        run.keep_env_memory()  # the last checkpoint is written after the pool closes (session.conclude),
        # so its reading is taken here, while the pool still answers
    # the model's story starts with the run whose weights it started from
    return run.session.conclude(run.checkpoint, run.agent.save, **({"init_from": run.parent} if run.parent else {}))


class RolloutLoop:
    """One PPO run's parts: the agent, its session and RNG, the rollout buffers, the halvings by rule, and
    what the envs build up (Mario: the restart routes, kept by checkpoints and lent between envs)."""

    def __init__(self, spec: RunSpec, envs: EnvPool):
        cfg, exp = spec.config, spec.experiment
        self.cfg, self.exp, self.envs = cfg, exp, envs
        obs_shape, n_actions = envs.single_observation_space.shape, int(envs.single_action_space.n)
        self.agent = PPOAgent(obs_shape, n_actions, cfg)
        if note := bfloat16_note(cfg.precision, cpu_flags()):
            tqdm.write(note)
        self.rng = np.random.default_rng(spec.seed)
        curriculum = exp.curriculum
        self.memory = curriculum.memory if curriculum else None
        state, arrays = checkpoints.restore(spec, self.agent, self.rng)
        if state is not None:
            self.parent = state.get("init_from")
            checkpoints.give_env_memory(envs, self.memory, arrays, curriculum.share_memory if curriculum else None, cfg)
        else:
            self.parent = init_weights(self.agent, cfg.init_from, exp.name, spec.algo) if cfg.init_from else None
        self.session = TrainingSession(spec, state, progress_unit="step")
        self.rollouts = int(state.get("rollouts", 0)) if state else 0
        self.lr = LearningRateHalving(cfg.lr, cfg.lr_halve_at, state)
        self.entropy = HalvingAtShares("entropy weight", cfg.entropy_coef, cfg.entropy_halve_at, state)
        self.agent.set_learning_rate(self.lr.rate())  # a resume comes back at the values its halvings left
        self.agent.set_entropy_coef(self.entropy.rate())
        self.env_kept: dict = {}  # what the envs built up, read while the pool is open
        self.buf = Rollout(cfg.n_steps, cfg.num_envs, obs_shape, self.agent.obs_dtype)
        self.running = np.zeros(cfg.num_envs)
        self.losses = {name: float("nan") for name in UPDATE_NAMES}  # CSV columns exist from the first row
        # a resumed run starts fresh episodes, reseeded from its episode count
        self.obs, _ = envs.reset(seed=self.session.fresh_env_seeds(cfg.num_envs))

    def checkpoint(self) -> None:
        checkpoints.save(self.session, self.agent, self.rng, env_arrays=self.env_kept, rollouts=self.rollouts,
                         init_from=self.parent, **{**self.lr.state(), **self.entropy.state()})  # one key, the best share

    def collect(self) -> tuple[RolloutLog, float]:
        """``n_steps`` steps of every env into the buffers; a truncated episode's final observation valued
        in one batched call per step; each ended episode's row to the session. Returns the rollout's log
        and its seconds."""
        log, truncated_values, started = RolloutLog(self.exp), {}, time.perf_counter()
        buf, session, n = self.buf, self.session, self.cfg.num_envs
        for step in range(self.cfg.n_steps):
            actions, logp, values = self.agent.act(self.obs, self.rng)
            next_obs, rewards, terminated, truncated, infos = self.envs.step(actions)
            done = terminated | truncated
            buf.obs[step], buf.actions[step], buf.logp[step], buf.values[step] = self.obs, actions, logp, values
            buf.rewards[step], buf.terminated[step], buf.dones[step] = rewards, terminated, done
            session.env_steps += n
            self.running += rewards
            log.step(infos)
            cut = np.flatnonzero(truncated & ~terminated)
            if len(cut):  # one batched call for every env cut by a time limit this step
                finals = self.agent.values(np.stack([infos["final_obs"][i] for i in cut]))
                truncated_values.update({(step, i): float(v) for i, v in zip(cut, finals)})
            for i in np.flatnonzero(done):
                row, won, counted = log.episode(infos, i, self.losses)
                session.end_episode(self.running[i], row, success=won, counted=counted)
                self.running[i] = 0.0
            self.obs = next_obs
            session.advance(n)
        buf.close(self.agent.values(self.obs), truncated_values)
        return log, round(time.perf_counter() - started, 3)  # where a rollout's time goes

    def learn(self) -> tuple[dict, float]:
        """One PPO update on the rollout (a NaN loss ends the run with one line); its losses and seconds."""
        started = time.perf_counter()
        with reported_divergence(self.session, "PPO", "lower the learning rate"):
            self.losses = self.agent.update(*self.buf.arrays(), self.rng)
        self.rollouts += 1
        return self.losses, round(time.perf_counter() - started, 3)

    def report(self, log: RolloutLog, losses: dict, seconds: dict) -> None:
        """The rollout's row and console line, the halvings the share has earned, a checkpoint when due."""
        session, book = self.session, self.session.book
        session.log_rollout(self.rollouts, {**log.row(), **losses, "lr": self.lr.rate(),
                                            "entropy_coef": self.entropy.rate(), **seconds})
        line = log.line(self.rollouts, session.env_steps, book, self.cfg.window)
        tqdm.write(line + f" | loss {losses['loss']:.3f} entropy {losses['entropy']:.2f}")
        for halving, apply in ((self.lr, self.agent.set_learning_rate), (self.entropy, self.agent.set_entropy_coef)):
            if halved := halving.observe(book.settled_success_share):
                apply(halving.rate())
                tqdm.write(halved)
        if self.rollouts % self.cfg.checkpoint_rollouts == 0:
            self.keep_env_memory()
            self.checkpoint()

    def keep_env_memory(self) -> None:
        self.env_kept = checkpoints.env_memory(self.envs, self.memory)


def init_weights(agent: PPOAgent, folder: str, experiment: str, algo: str) -> dict:
    """Load the weights of the model folder ``folder`` (``--init-from``) into ``agent``; return what
    that model was (its path, training commands, env steps, wall time, evaluation) for meta.json."""
    from rlcore.networks.saving import load_keras_model
    from rlcore.training.init_from import init_from_meta

    meta = init_from_meta(folder, experiment, algo, MODEL_FILE)  # checked in build_spec too, before any env starts
    try:
        source = load_keras_model(Path(folder) / MODEL_FILE, agent.obs_shape, agent.n_actions)
    except UserError as exc:  # a missing, damaged or wrong-shaped model: named as the setting that gave it
        raise UserError(f"{flag('init_from')}: {exc}") from None
    agent.set_weights(source.get_weights())
    keep = ("config", "commands", "env_steps", "episodes", "wall_seconds", "evaluation", "init_from")
    return {"path": str(folder), **{k: meta[k] for k in keep if k in meta}}
