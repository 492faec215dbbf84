"""The command line (deeprl, or python main.py): the parser built from the configs, and one module per group of commands.

May import: anything in rlcore; nothing imports it but main.py and the API's shared limits come from rlcore.hyperparams.
"""
