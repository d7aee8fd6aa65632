"""What the rod and the plate share: clamps on DOFs, a banded Hessian, a contiguous free block.

Both models order their DOFs so the clamped ones come first and last and the free ones form one
contiguous block `free`; the Hessian is a SymmetricBanded (ddg.solve.banded).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..solve.banded import SymmetricBanded


@dataclass
class Evaluation:
    energy: float
    gradient: np.ndarray | None = None
    hessian: SymmetricBanded | None = None
    parts: dict | None = None
    frames: tuple | None = None  # rod only: (tangents, d1, m_ref) of the evaluated state


class BandedModel:
    n_dof: int
    free: slice
    constrained: np.ndarray

    def _accumulators(self, gradient: bool, hessian: bool) -> tuple[np.ndarray, np.ndarray]:
        """Zeroed gradient and flattened lower band for the compiled kernels to add into (empty
        where not asked)."""
        n = self.n_dof
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
