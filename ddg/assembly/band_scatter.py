"""Compiled scatter of element blocks into symmetric lower band storage (LAPACK form).

Band storage: band[d, j] = A[j + d, j], 0 <= d <= bandwidth, for an n x n matrix; with the band
flattened (C order) the entry (r, c), r >= c, sits at (r - c) * n + c. Element kernels (the rod's
stencils and edges, the plate's edges, triangles and hinges) call these helpers for every element
as they compute it, so no per-element block arrays are formed in the assembled evaluation.

The band of a plate is large (tens of MB) and an element's entries lie on as many rows of it as
the element has DOF differences, so adding them waits on memory; `prefetch_lower` asks the
processor to fetch the next element's entries while the current one is computed (a hint: no
effect on any value).
"""
from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def _prefetch(typingctx, array, index):
    """llvm.prefetch (for writing, kept in all cache levels) of array[index] of a 1-D array."""
    def codegen(context, builder, signature, args):
        array_type = signature.args[0]
        array_struct = context.make_array(array_type)(context, builder, args[0])
        pointer = cgutils.get_item_pointer(context, builder, array_type, array_struct, [args[1]], wraparound=False)
        byte_pointer = ir.IntType(8).as_pointer()
        i32 = ir.IntType(32)
        signature_ir = ir.FunctionType(ir.VoidType(), [byte_pointer, i32, i32, i32])
        function = cgutils.get_or_insert_function(builder.module, signature_ir, "llvm.prefetch")
        builder.call(function, [builder.bitcast(pointer, byte_pointer), ir.Constant(i32, 1), ir.Constant(i32, 3),
                                ir.Constant(i32, 1)])
        return context.get_dummy_value()
    return types.void(array, index), codegen


@njit(cache=True, forceinline=True)
def prefetch_lower(band, n, dofs, m):
    """Prefetch the lower entries (r >= c) of the flattened band among the first m of dofs."""
    for a in range(m):
        r = dofs[a]
        for b in range(a + 1):
            c = dofs[b]
            _prefetch(band, abs(r - c) * n + min(r, c))


@njit(cache=True, forceinline=True)
def add_entry(band, n, r, c, value):
    """A[r, c] += value and (by symmetry) A[c, r] += value, in lower storage."""
    if r >= c:
        band[(r - c) * n + c] += value
    else:
        band[(c - r) * n + r] += value


@njit(cache=True)
def add_symmetric_block(band, n, dofs, block):
    """A[dofs, dofs] += block for a symmetric block with distinct global DOFs: each global pair
    receives its entry once (from the (a, b) with dofs[a] >= dofs[b])."""
    m = dofs.shape[0]
    for a in range(m):
        r = dofs[a]
        for b in range(m):
            c = dofs[b]
            if r >= c:
                band[(r - c) * n + c] += block[a, b]


@njit(cache=True)
def add_pair_block(band, n, rows, cols, block):
    """A += C + C^T with C = block on (rows, cols): each entry lands once in the lower band, twice
    where a row DOF equals a column DOF (the diagonal of the shared nodes)."""
    for a in range(rows.shape[0]):
        r = rows[a]
        for b in range(cols.shape[0]):
            c = cols[b]
            if r > c:
                band[(r - c) * n + c] += block[a, b]
            elif r < c:
                band[(c - r) * n + r] += block[a, b]
            else:
                band[c] += 2.0 * block[a, b]


@njit(cache=True)
def band_matvec(band, x):
    """y = A x for the symmetric matrix in lower band storage band (bandwidth + 1, n)."""
    n = band.shape[1]
    y = np.empty(n)
    for j in range(n):
        y[j] = band[0, j] * x[j]
    for d in range(1, band.shape[0]):
        for j in range(n - d):
            v = band[d, j]
            y[j + d] += v * x[j]
            y[j] += v * x[j + d]
    return y
