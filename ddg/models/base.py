"""What the rod and the plate share: clamps on DOFs, a banded Hessian, a contiguous free block.

Both models order their DOFs so the clamped ones come first and last and the free ones form one
contiguous block `free`; the Hessian is a SymmetricBanded (ddg.solve.banded).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from ..solve.allocation import keep_large_blocks
from ..solve.banded import SymmetricBanded


@dataclass
class Evaluation:
    energy: float
    gradient: np.ndarray | None = None
    hessian: SymmetricBanded | None = None
    parts: dict | None = None
    frames: tuple | None = None  # rod only: (tangents, d1, m_ref) of the evaluated state


@runtime_checkable
class Model(Protocol):
    """What the one driver (ddg.protocol.driver), Newton (ddg.solve.newton), the continuation
    (ddg.solve.continuation) and the stability analysis (ddg.solve.stability) call on a model.
    Every entry of the registry (ddg.models.registry) is one. SI units throughout.

    The DOFs: n_dof of them, the clamped ones (`constrained`) first and last, the free ones one
    contiguous block `free`; the Hessian a SymmetricBanded of half-bandwidth `bandwidth`."""

    name: str
    strip: object
    n_dof: int
    bandwidth: int
    free: slice
    constrained: np.ndarray

    def evaluate(self, q: np.ndarray, gradient: bool = True, hessian: bool = True) -> Evaluation:
        """Energy (J), gradient and banded Hessian at q (m, rad)."""

    def commit(self, q: np.ndarray, evaluation: Evaluation | None = None) -> None:
        """q is the accepted state: the reference the next evaluations are transported from."""

    def clamp_values(self, compression: float, shear: float) -> np.ndarray:
        """The clamped DOFs' values at end shortening `compression` and clamp shift `shear` (m)."""

    def apply_clamps(self, q: np.ndarray, compression: float, shear: float) -> np.ndarray:
        """q with its clamped DOFs set (a copy)."""

    def buckled_guess(self, compression: float) -> np.ndarray:
        """A state near the buckled U at end shortening `compression` (m)."""

    def free_matrix(self, hessian: SymmetricBanded) -> SymmetricBanded:
        """The Hessian restricted to the free DOFs."""

    def coupling(self, hessian: SymmetricBanded, dq_constrained: np.ndarray) -> np.ndarray:
        """The free rows of the Hessian times a change of the clamped DOFs."""

    def residual_scale(self) -> np.ndarray:
        """Per DOF, the force (N) or moment (N m) that makes its residual dimensionless."""

    def length_scale(self) -> np.ndarray:
        """Per DOF, the length (m) or angle (rad) that makes its correction dimensionless."""

    def residual_floor(self) -> float:
        """The round-off floor of the scaled residual."""

    def midpoint(self, q: np.ndarray) -> np.ndarray:
        """The centerline's midpoint (m)."""

    def centerline_positions(self, q: np.ndarray, stations: int):
        """The centerline at `stations` points along it (m)."""


class BandedModel:
    n_dof: int
    free: slice
    constrained: np.ndarray

    def _accumulators(self, gradient: bool, hessian: bool) -> tuple[np.ndarray, np.ndarray]:
        """Zeroed gradient and flattened lower band for the compiled kernels to add into (empty
        where not asked)."""
        n = self.n_dof
        if hessian:
            keep_large_blocks(8 * (self.bandwidth + 1) * n)  # plates: no page faults per iteration
        return (np.zeros(n) if gradient else np.empty(0),
                np.zeros((self.bandwidth + 1) * n) if hessian else np.empty(0))

    def _evaluation(self, parts: dict, grad: np.ndarray, band: np.ndarray, gradient: bool, hessian: bool,
                    frames=None) -> Evaluation:
        out = Evaluation(energy=sum(parts.values()), parts=parts, frames=frames)
        if gradient:
            out.gradient = grad
        if hessian:
            out.hessian = SymmetricBanded(band.reshape(self.bandwidth + 1, self.n_dof))
        return out

    def apply_clamps(self, q: np.ndarray, compression: float, shear: float) -> np.ndarray:
        q = q.copy()
        q[self.constrained] = self.clamp_values(compression, shear)
        return q

    def free_matrix(self, hessian: SymmetricBanded) -> SymmetricBanded:
        """Hessian restricted to the free DOFs (a contiguous block of the band), cached on it."""
        block = getattr(hessian, "_free_block", None)
        if block is None:
            block = hessian.restrict(self.free.start, self.free.stop)
            hessian._free_block = block
        return block

    def coupling(self, hessian: SymmetricBanded, dq_constrained: np.ndarray) -> np.ndarray:
        """H_fc dq_c: the force change on the free DOFs from moving the clamps by dq_c."""
        dq = np.zeros(self.n_dof)
        dq[self.constrained] = dq_constrained
        return hessian.matvec(dq)[self.free]
