"""The Python API: what ``main.py`` does, from a notebook or a script, with the same records.

May import: everything in rlcore but the command line (its limits come from rlcore.hyperparams.limits).

    from rlcore import api

    run = api.train("Acrobot-v1", "dqn", episodes=200, lr=5e-4)        # any Gymnasium id, or an experiment
    run.evaluation["mean"]                                              # the final unseen-seed evaluation
    run = api.resume(run, episodes=400)                                 # on from its checkpoint, as --resume
    policy = api.load(("lunar_lander", "dqn"))                          # a shipped model, or any model folder
    action = policy.predict(observation)
    api.evaluate(policy, episodes=20)                                   # -> dict, as `main.py evaluate`
    api.render(policy, "lander.gif")                                    # MP4 or GIF
    api.export(run, "onnx", "exports/acrobot")                          # checked against the Keras model

:func:`train` and :func:`resume` (:mod:`rlcore.api.training`) run what ``main.py train`` runs
(:func:`rlcore.training.run.train_and_evaluate`): the same checked hyperparameters, run folder, checkpoints,
CSV tables and model folder, and the same final evaluation on unseen seeds written into meta.json,
whose ``command`` records this call. A mistake
the user can fix raises :class:`UserError` (one line, as the CLI prints it). TensorFlow is imported
on the first call that needs it, with its start-up noise dropped; progress bars are widgets in a
notebook (``tqdm.auto``).
"""
from rlcore.api.models import ExportFormat, ModelRef, Policy, Run, evaluate, export, load, render
from rlcore.api.training import ProgressCallback, WandbMode, resume, train
from rlcore.environments.experiment import Experiment
from rlcore.errors import UserError
from rlcore.training.stopping import Interrupted

__all__ = ["train", "resume", "load", "evaluate", "render", "export", "Run", "Policy", "ModelRef",
           "ProgressCallback", "WandbMode", "Experiment", "UserError", "Interrupted", "ExportFormat"]
