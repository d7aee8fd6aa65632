"""Fixtures shared by several test modules."""
import signal

import pytest


def pytest_configure(config):
    """The Ctrl-C tests need Python's own SIGINT handler: a suite started in the background by a
    shell without job control (`cmd &` in a script, nohup) inherits SIGINT ignored, and the
    commands rightly keep an ignored SIGINT ignored (ddg.output.interrupts)."""
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def plate_sixth_fine():
    """The plate of the clamp-force comparisons with the FEM (tests/ddg/models/test_shear_force.py; W/L = 1/6,
    dL/L = 1/2) on the 5740-triangle mesh their measured figures and bounds refer to, with the quick
    shear sampling (60 steps): about 2 minutes on 2 cores, run once."""
    import ddg

    strip = ddg.Strip.from_ratios(width_ratio=1 / 6, compression_ratio=1 / 2)
    protocol = ddg.LoadingProtocol(1 / 2, compression_steps=40, shear_steps=60)
    result = ddg.simulate(strip, protocol, model="plate", resolution=6000, branches=False)
    assert result.converged, result.summary["message"]
    return result


@pytest.fixture
def restore_signal_handlers():
    """main() installs SIGINT/SIGTERM handlers (ddg.output.interrupts.terminate_as_interrupt): restore them."""
    import signal

    saved = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    yield
    for sig, handler in saved.items():
        if handler is not None:
            signal.signal(sig, handler)
