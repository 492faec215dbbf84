"""``python -m tools.docgen [--check]``: see :mod:`tools.docgen.main`."""
from tools.docgen.main import main

raise SystemExit(main())
