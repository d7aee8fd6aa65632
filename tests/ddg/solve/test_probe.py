"""The public timing/callback interface (ddg.solve.probe): what benchmarks measure through."""
from __future__ import annotations

from collections import Counter

import pytest

import ddg
from ddg.solve.continuation import PHASES
from ddg.solve.probe import Probe


class Recording(Probe):
    def __init__(self):
        self.solves, self.steps = [], []

    def solve(self, phase, iterations, converged):
        self.solves.append((phase, iterations, converged))

    def step(self, stage, row, wall_s):
        self.steps.append((stage, row, wall_s))


def test_a_probe_sees_every_solve_and_every_recorded_step():
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    protocol = ddg.LoadingProtocol(0.5, compression_steps=5, shear_steps=30)
    probe = Recording()
    result = ddg.simulate(strip, protocol, model="rod", resolution=30, branches=False, probe=probe)
    assert result.converged
    # every recorded row, in order, with a positive wall time
    assert [row for _, row, _ in probe.steps] == result.rows
    assert all(wall > 0 for _, _, wall in probe.steps)
    # the solves add up to the path's iterations, phase by phase
    by_phase = Counter()
    for phase, iterations, _ in probe.solves:
        assert phase in PHASES
        by_phase[phase] += iterations
    assert sum(by_phase.values()) == result.summary["newton_iterations"]
    for phase in PHASES:
        assert by_phase[phase] == result.summary["newton_iterations_by_phase"][phase]
    assert all(converged for phase, _, converged in probe.solves if phase == "accepted steps")
    assert not any(converged for phase, _, converged in probe.solves if phase == "rejected steps")


def test_a_probe_changes_nothing():
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    protocol = ddg.LoadingProtocol(0.5, compression_steps=5, shear_steps=10)
    plain = ddg.simulate(strip, protocol, model="rod", resolution=20, branches=False)
    probed = ddg.simulate(strip, protocol, model="rod", resolution=20, branches=False, probe=Recording())
    assert probed.rows == plain.rows


def test_a_probe_must_be_a_probe():
    strip = ddg.Strip.from_ratios(0.05, 0.5)
    with pytest.raises(ddg.InputError, match="probe"):
        ddg.simulate(strip, ddg.LoadingProtocol(0.5), probe=print)
