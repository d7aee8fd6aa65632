"""What made the kernels slow to compile must not come back: numba's IR-level inlining
(`inline="always"`, which types the caller again at every call site; the hot helpers are inlined by
LLVM instead, `forceinline=True`), one compiled energy with every model's terms, and second
specialisations for constant (Literal) arguments of the kernels that link the most code. The
seconds are measured by benchmarks/compile_time.py (docs/findings/measured.md), never asserted here."""
import re
from pathlib import Path

import pytest

DDG = Path(__file__).resolve().parents[2] / "ddg"


def test_no_kernel_asks_numba_to_inline_it():
    offenders = [f"{path.relative_to(DDG.parent)}:{number}"
                 for path in sorted(DDG.rglob("*.py"))
                 for number, line in enumerate(path.read_text().splitlines(), 1)
                 if re.search(r"njit\(.*[(,]\s*inline\s*=", line)]
    assert not offenders, (f"numba IR inlining re-types the caller at every call site: {offenders}; "
                           "forceinline=True asks LLVM instead")


def test_the_rod_family_energy_is_compiled_apart_per_kind_of_terms():
    from ddg.models import rod_assembly

    kinds = set(rod_assembly.KIND_NAMES)
    assert set(rod_assembly.ENERGIES) == kinds
    assert set(rod_assembly.LOOPS) == kinds
    assert len({id(f) for loops in rod_assembly.LOOPS.values() for f in loops}) == 2 * len(kinds)
    assert len({id(f) for f in rod_assembly.ENERGIES.values()}) == len(kinds)


@pytest.mark.slow
def test_a_rod_user_compiles_each_large_kernel_once_and_no_ribbon_terms():
    """From an empty cache (a scratch copy), the rod's warm-up part: the energy and the loops that
    link it are compiled for one signature each, and none of the wide ribbons' kernels is compiled."""
    from benchmarks.compile_time import compile_group

    result = compile_group(["rod"], timeout=900)
    assert "kernels" in result, result
    kernels = result["kernels"]
    linking = [k for k in kernels if re.search(r"rod_assembly\._rod_energy|compiled_newton\._(newton|arclength)", k)]
    assert linking, sorted(kernels)
    assert all(len(kernels[k]["signatures"]) == 1 for k in linking), {k: kernels[k]["signatures"] for k in linking}
    ribbons = [k for k in kernels if re.search(r"trapeze|wunderlich|cross_section", k)]
    assert not ribbons, ribbons
