"""Files a run writes and reads back: atomic writes, the checkpoint's .npz format, one writer per run folder.

May import: rlcore.errors only.
"""
