"""The model cards' GIFs (``make gifs``): each shipped model plays one episode into
``docs/assets/gifs/<experiment>_<model>.gif`` through the ordinary ``render`` command, on a stated seed:
the first seed of its recorded evaluation on unseen seeds, or for a model with a goal (Mario's flag) the
first seed on which that evaluation reached it, so the picture shows what the score counts. ``render``
prints whether the episode did so again.

    python -m tools.gifs               # every shipped model
    python -m tools.gifs --missing     # only the cards without a GIF yet
    python -m tools.gifs mario_ppo_1-2 lunar_lander_a2c
"""
from __future__ import annotations

import argparse
import subprocess
import sys

from tools.docgen.data import REPO, shipped_models

GIFS = "docs/assets/gifs"


def gif_seed(evaluation: dict) -> int:
    """The first evaluation seed whose episode succeeded (a goal's), else the first seed evaluated."""
    episodes = evaluation.get("per_episode") or []
    won = [e["seed"] for e in episodes if e.get("success")]
    if won:
        return int(won[0])
    if episodes:
        return int(episodes[0]["seed"])
    return int(str(evaluation.get("seeds", "1000000")).split("..")[0])


def render_command(model) -> list[str]:
    return [sys.executable, "main.py", "render", model.experiment, model.algo, "--model", model.folder,
            "--seed", str(gif_seed(model.evaluation)), "--episodes", "1", "--out", f"{GIFS}/{model.slug}.gif"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.gifs", description=__doc__.split("\n\n")[0])
    parser.add_argument("slugs", nargs="*", help="only these cards (experiment_model, e.g. mario_ppo_1-2)")
    parser.add_argument("--missing", action="store_true", help="only the cards without a GIF yet")
    args = parser.parse_args(argv)
    models = [m for m in shipped_models() if (not args.slugs or m.slug in args.slugs)
              and not (args.missing and m.gif)]
    unknown = set(args.slugs) - {m.slug for m in shipped_models()}
    if unknown:
        parser.error(f"no shipped model {', '.join(sorted(unknown))}")
    for model in models:
        command = render_command(model)
        print(" ".join(["python", *command[1:]]), flush=True)
        if subprocess.call(command, cwd=REPO) != 0:
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
