"""The commands that read run and sweep folders: ``plot``, ``status``, ``sweep`` (which starts or
resumes one) and ``report``."""
from __future__ import annotations

from pathlib import Path

from rlcore.errors import UserError
from rlcore.files.atomic import writable_folder


def _run_folder(run_dir: Path) -> dict:
    """What the run in ``run_dir`` trained (:func:`rlcore.records.status.run_record`: its model's meta.json once
    finished, its checkpoint's state while training or resumed past its model); a folder with neither,
    or without metrics.csv, is a clear error."""
    from rlcore.records.status import run_record

    if not run_dir.is_dir():
        what = "is a file" if run_dir.exists() else "no such folder"
        raise UserError(f"{run_dir}: {what}; give a run folder such as runs/<name>")
    if not (run_dir / "metrics.csv").is_file():
        raise UserError(f"no metrics.csv in {run_dir}; give a run folder such as runs/<name>")
    record = run_record(run_dir)
    if record is None:
        raise UserError(f"{run_dir} has neither a checkpoint nor a model/meta.json to say what it trained")
    return record


def cmd_plot(args) -> int:
    from rlcore.environments.registry import get_experiment
    from rlcore.records.plotting import plot_run

    run_dir = Path(args.run_dir)
    about = _run_folder(run_dir)
    out_dir = Path(args.out) if args.out else run_dir / "plots"
    writable_folder(out_dir, "--out")
    for path in plot_run(run_dir, out_dir, get_experiment(about["experiment"]), about):
        print(f"plot:    {path}")
    return 0


def cmd_status(args) -> int:
    from rlcore.environments.registry import get_experiment
    from rlcore.records.status import run_status

    run_dir = Path(args.run_dir)
    if (run_dir / "sweep.json").is_file():  # a sweep's folder: a line per trial
        from rlcore.sweeps.status import sweep_status
        print("\n".join(sweep_status(run_dir)))
        return 0
    about = _run_folder(run_dir)
    print("\n".join(run_status(run_dir, get_experiment(about["experiment"]), about, args.block, args.blocks,
                                      args.rollout_block)))
    return 0


def cmd_sweep(args) -> int:
    from rlcore.environments.registry import get_experiment
    from rlcore.host.extras import require
    from rlcore.sweeps.on_ray import run_sweep
    from rlcore.sweeps.sweep import Sweep, parse_grid, parse_seeds
    from rlcore.training.run import budget_overrides

    require("ray.tune", "The sweep command")  # the sweep extra, or one line saying so
    exp = get_experiment(args.experiment, env_kwargs=args.env_kwargs)
    base = exp.preset(args.algo, args.preset)
    name = args.name or f"{args.experiment}__{args.algo}"
    folder = (Path(args.dir) / name).resolve()
    if args.resume:
        sweep = Sweep.load(folder)
        if args.env_kwargs is not None and args.env_kwargs != (sweep.env_kwargs or {}):
            raise UserError(f"--env-kwargs cannot change on a resume: sweep {name} runs with {sweep.env_kwargs or 'none'}")
        if (sweep.experiment, sweep.algo) != (args.experiment, args.algo):
            raise UserError(f"sweep {name} runs {sweep.experiment} {sweep.algo}, "
                            f"not {args.experiment} {args.algo}")
    else:
        if (folder / "sweep.json").exists():
            raise UserError(f"sweep {name} exists in {folder}; continue it with --resume or pick another --name")
        sweep = Sweep(args.experiment, args.algo, name, str(folder), parse_seeds(args.seeds),
                      parse_grid(args.grid, base), args.preset, budget_overrides(args.episodes, args.steps), args.cpus_per_run,
                      args.max_concurrent, args.final_eval_episodes, args.env_kwargs)
    trials = sweep.trials()
    print(f"sweep {name}: {len(trials)} trials of {sweep.experiment} {sweep.algo} -> {folder}/")
    rows = run_sweep(sweep, address=args.address, num_cpus=args.num_cpus)
    for row in sorted(rows, key=lambda r: r["trial"]):
        if row.get("error"):
            status = f"failed: {row['error']}"
        elif row.get("not_started"):
            status = "not started (--resume starts it)"
        elif row.get("interrupted"):
            status = "stopped at a checkpoint (--resume continues it)"
        else:
            status = (f"final score {row.get('final_score', float('nan')):.3f}, "
                      f"{row.get('env_steps', 0):,} env steps"
                      + (" (finished earlier)" if row.get("skipped") else ""))
        print(f"  {row['trial']}: {status}")
    print(f"report: python main.py report {folder}")
    return 130 if (folder / "STOP").exists() else 0


def cmd_report(args) -> int:
    from rlcore.host.extras import require
    from rlcore.records.keeping import KEPT_FILES, is_run_folder, keep, keep_runs
    from rlcore.records.report import markdown, summarize
    from rlcore.records.report_plots import SUCCESS_SHARE, plot_critic, plot_curves, plot_evals

    require("rliable.metrics", "The report command")  # the sweep extra, or one line saying so
    folders = [Path(d) for d in args.sweep_dirs]
    runs = [d for d in folders if is_run_folder(d)]
    if runs and not args.keep:
        raise UserError(f"{runs[0]} is a finished run, not a sweep: to report single runs of one recipe over "
                        f"seeds, keep them together first (--keep DIR)")
    if args.keep:
        if runs and len(runs) != len(folders):
            raise UserError("--keep takes one sweep folder, or finished run folders only, not both")
        if not runs and len(folders) != 1:
            raise UserError("--keep copies one sweep: give one SWEEP_DIR with it")
        folders = [keep_runs(runs, Path(args.keep)) if runs else keep(folders[0], Path(args.keep))]
        print(f"kept: {folders[0]} (sweep.json; per run {', '.join(KEPT_FILES)}, where the run has them)")
    out = _report_folder(folders, args.out)
    result = summarize(folders, reps=args.reps)
    text = markdown(result)
    print(text)
    if out is None:
        print("written: nothing (a report of several sweeps goes where --out DIR says; each sweep's own "
              "report.md is left as it is)")
        return 0
    from rlcore.files.atomic import write_atomic
    out.mkdir(parents=True, exist_ok=True)  # after the summary: a sweep that cannot be read leaves no folder
    write_atomic(out / "report.md", lambda p: p.write_text(text + "\n"), then="report again")
    figures = {"report_curves.png": lambda path: plot_curves(result, path),
               "report_success.png": lambda path: plot_curves(result, path, column=SUCCESS_SHARE),
               "report_evals.png": lambda path: plot_evals(result, path),
               "report_critic.png": lambda path: plot_critic(result, path)}
    pngs = []
    for name, draw in figures.items():
        pngs.append(draw(out / name))
        if pngs[-1] is None:  # nothing to draw now: an earlier report's figure would describe other runs
            (out / name).unlink(missing_ok=True)
    print(f"written: {out / 'report.md'}, {', '.join(str(p) for p in pngs if p)}")
    return 0


def _report_folder(folders: list[Path], out: str | None) -> Path | None:
    """Where a report goes: ``--out``, else the one sweep's folder; None for several
    sweeps without ``--out`` (writing into the first would replace that sweep's own report)."""
    if out is None:
        return folders[0] if len(folders) == 1 else None
    folder = Path(out)
    if folder.is_file():
        raise UserError(f"--out {out}: a file, not a folder")
    if len(folders) > 1 and any(folder.resolve() == f.resolve() for f in folders):
        raise UserError(f"--out {out} is one of the sweeps reported: its own report.md would be replaced by a "
                        f"comparison; give another folder")
    return folder
