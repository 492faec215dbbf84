"""The command line's parser class: a bad command line is one line and exit status 2, no flag is
abbreviated, and an unknown flag is answered with the nearest one the command has, or with ours for the
name Stable-Baselines3, RL Zoo or CleanRL give it. The commands and their flags: :mod:`rlcore.cli.parser`.
"""
from __future__ import annotations

import argparse
import difflib

# the names Stable-Baselines3, RL Zoo and CleanRL give these settings -> ours, each where a command has it
# (--learning-rate is nearest --learning-starts by spelling, which is another setting)
OTHER_NAMES = {"--learning-rate": ("--lr", "--actor-lr", "--critic-lr"), "--n-envs": ("--num-envs",), "--num-steps": ("--n-steps",),
               "--total-timesteps": ("--steps",), "--n-timesteps": ("--steps",), "--n-epochs": ("--epochs",),
               "--update-epochs": ("--epochs",), "--ent-coef": ("--entropy-coef",), "--vf-coef": ("--value-coef",),
               "--clip-range": ("--clip",), "--clip-coef": ("--clip",), "--batch": ("--batch-size", "--minibatch"),
               "--num-minibatches": ("--minibatch",), "--max-grad": ("--max-grad-norm",), "--env": ("EXPERIMENT",),
               "--env-id": ("EXPERIMENT",), "--algo": ("ALGO",), "--net-arch": ("--hidden", "--actor-hidden", "--critic-hidden")}


def _nearest(flag: str, options) -> list[str]:
    """Ours for another library's name (``--learning-rate``: ``--lr``), else the one flag ``flag`` begins
    (``--epi``: ``--episodes``), else the closest spelling (``--gama``), else none."""
    ours = [name for name in OTHER_NAMES.get(flag, ()) if name in options or name.isupper()]
    if ours:
        return [f"the positional {name}" if name.isupper() else name for name in ours]
    starting = [option for option in options if option.startswith(flag)]
    return starting if len(starting) == 1 else difflib.get_close_matches(flag, list(options), n=1, cutoff=0.75)


class CommandParser(argparse.ArgumentParser):
    """argparse that reports a bad command line as one line (and exit status 2), takes no abbreviated flag
    (``--epi`` is not ``--episodes``), and answers a flag it does not know in the words of the command it was
    given to, with the nearest flag that command has."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message):
        hint = f"{self.prog} EXPERIMENT ALGO --help" if self.prog.endswith(" train") else f"{self.prog} --help"
        self.exit(2, f"error: {message} (see `{hint}`)\n")

    def parse_args(self, args=None, namespace=None):
        known, unknown = self.parse_known_args(args, namespace)
        if unknown:
            command = self._command_parser(known)
            flags = unknown[:unknown.index("--")] if "--" in unknown else unknown  # after --: not flags
            near = [match for flag in flags if flag.startswith("--")
                    for match in _nearest(flag.split("=")[0], command._option_string_actions) if match != flag]
            command.error(f"unrecognized arguments: {' '.join(unknown)}"
                          + (f"; did you mean {', '.join(near)}?" if near else ""))
        return known

    def _command_parser(self, known) -> argparse.ArgumentParser:
        """The subcommand's parser (``main.py train``) a namespace was parsed by, else this one."""
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                return action.choices.get(getattr(known, action.dest, None), self)
        return self


class Unparsable(Exception):
    """What QuietParser raises where CommandParser would exit."""


class QuietParser(argparse.ArgumentParser):
    """A parser for a first, forgiving look at a command line: an error is raised, not printed."""

    def error(self, message):
        raise Unparsable(message)
