"""Scripts that drive the package from a checkout (the docs generator); not installed with it."""
