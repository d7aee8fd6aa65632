"""`python -m validation.error_map`: the old spelling of `python -m validation error-map`."""
from .command import main

if __name__ == "__main__":
    raise SystemExit(main())
