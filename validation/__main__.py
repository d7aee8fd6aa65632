"""`python -m validation <command> [options]` (validation.cli): report, score, benchmark, error-map,
plate-gold, narrow-limit, wide-check, locking, plate-modes, plate-mesh-scan, paper-figures,
ribbon-regularisation; `python -m validation --help` lists them, `python -m validation <command>
--help` gives a command's options."""
from __future__ import annotations

from .cli import main
from .report import check_report_inputs

__all__ = ["check_report_inputs", "main"]

if __name__ == "__main__":
    raise SystemExit(main())
