"""`python -m ddg`: the command line (ddg.cli)."""
import sys

from .cli import main

sys.exit(main())
