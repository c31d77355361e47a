"""`python -m fswkit.cli`: the `fsw` command."""

import sys

from fswkit.cli import main

sys.exit(main())
