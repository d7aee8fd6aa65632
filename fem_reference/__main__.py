"""`python -m fem_reference`: the command line (fem_reference.cli)."""
from .cli import main

raise SystemExit(main())
