#!/usr/bin/env python3
"""The package's command line, run from a checkout: ``python main.py --help``.

Installed, the same command line is the ``deeprl`` script (``deeprl --help``); both call
:func:`rlcore.cli.main.main`. TensorFlow is imported only inside the commands that need it.
"""
import sys

from rlcore.cli.main import COMMANDS, build_parser, main  # noqa: F401  (tests and scripts use these names)

if __name__ == "__main__":
    sys.exit(main())
