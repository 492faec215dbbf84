"""The docs generator moved out of the installed package: it reads the checkout, not the package."""
import sys

if __name__ == "__main__":
    sys.exit("rlcore.docgen moved: run `python -m tools.docgen` (or `make docs`) from a checkout of the repository")
