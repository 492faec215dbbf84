"""What this machine and install have: the CPU's name and vector units, whether a record replays exactly here, the optional extras, a quiet console.

May import: rlcore.errors, rlcore.files.
"""
