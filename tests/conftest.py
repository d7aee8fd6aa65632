"""Fixtures shared by several test modules."""
import pytest


@pytest.fixture(scope="session")
def plate_sixth_fine():
    """The plate of the plate-vs-FEM comparisons (W/L = 1/6, dL/L = 1/2) at the validation report's
    CROSS_MODEL_PLATE triangles (5740) and its quick shear sampling (60 steps): about 2 minutes on
    2 cores, run once for the default suite's plate-vs-FEM checks (issue 7: quick versions in the
    default run) in tests/test_fem_cross_model.py and tests/test_validation.py."""
    import ddg
    from validation.studies import CROSS_MODEL_PLATE

    strip = ddg.Strip.from_ratios(width_ratio=1 / 6, compression_ratio=1 / 2)
    protocol = ddg.LoadingProtocol(1 / 2, compression_steps=40, shear_steps=60)
    result = ddg.simulate(strip, protocol, model="plate", resolution=CROSS_MODEL_PLATE, branches=False)
    assert result.converged, result.summary["message"]
    return result
