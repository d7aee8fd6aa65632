"""The shell's finite elements (fem_reference.shell.NaghdiStrip), described without dolfinx so that
an element name is checked and a mesh's unknowns counted before any FEM import.

* "P2B3" (the default; FEniCSx-Shells' demo, Arnold & Brezzi 1997): u in [P2 + B3]^3 (quadratic
  Lagrange enriched by the cubic bubble), theta in [P2]^2; PSRI rules of degree 4 (6 Gauss
  points) and 2 (3 points).
* "P3": u in [P3]^3, theta in [P3]^2. P3 contains P2 + B3 (the cubic bubble is a P3 function),
  so on one mesh it holds the default element's fields and more. basix 0.5 offers no quartic
  bubble without the cubic one (its degree-4 bubble space is B3 x P1, which already contains B3,
  so P3 + B4 would be linearly dependent), hence no enrichment. PSRI rules of degree 6 (12
  points) and 4 (6 points), chosen as for P2B3: the full rule is exact for the linearised energy
  of the element's highest-degree terms (|gamma|^2 with theta of degree k: 2k), the reduced rule
  two degrees lower (exact for the membrane energy of the Lagrange part, (grad P_k)^2: 2k - 2).

ShellElement.n_dof counts the unknowns on the structured strip mesh (fem_reference.mesh).
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ShellElement:
    """u in [P_degree + B_bubble]^3 (bubble 0: none), theta in [P_rotation_degree]^2, PSRI with
    Gauss rules exact to full_degree and reduced_degree."""

    name: str
    degree: int
    bubble: int
    rotation_degree: int
    full_degree: int
    reduced_degree: int

    @property
    def description(self) -> str:
        """summary.json's mesh.element."""
        u = f"P{self.degree} + B{self.bubble}" if self.bubble else f"P{self.degree}"
        return f"Naghdi shell: u in [{u}]^3, theta in [P{self.rotation_degree}]^2"

    @property
    def locking(self) -> str:
        """summary.json's mesh.locking."""
        return f"PSRI, alpha = b^2/h^2, full degree {self.full_degree}, reduced degree {self.reduced_degree}"

    def n_dof(self, nx: int, ny: int) -> int:
        """Unknowns on the structured nx x ny mesh (2 nx ny triangles, alternating diagonals):
        a degree-k Lagrange field has one node per vertex, k - 1 per edge and (k-1)(k-2)/2 per
        triangle; a degree-b bubble (b-1)(b-2)/2 per triangle."""
        vertices = (nx + 1) * (ny + 1)
        edges = nx * (ny + 1) + ny * (nx + 1) + nx * ny
        triangles = 2 * nx * ny

        def lagrange(k: int) -> int:
            return vertices + (k - 1) * edges + (k - 1) * (k - 2) // 2 * triangles

        bubbles = (self.bubble - 1) * (self.bubble - 2) // 2 * triangles if self.bubble else 0
        return 3 * (lagrange(self.degree) + bubbles) + 2 * lagrange(self.rotation_degree)


ELEMENTS = {"P2B3": ShellElement("P2B3", 2, 3, 2, 4, 2), "P3": ShellElement("P3", 3, 0, 3, 6, 4)}
DEFAULT_ELEMENT = "P2B3"


def check_element(value, name: str = "element") -> ShellElement:
    """The ShellElement named `value`, or a one-line ddg InputError."""
    from ddg.geometry.strip import InputError

    if not isinstance(value, str) or value not in ELEMENTS:
        raise InputError(f"{name} = {value!r} is not one of {', '.join(ELEMENTS)} "
                         f"(P2B3: u in [P2 + B3]^3, theta in [P2]^2, the default; P3: u in [P3]^3, theta in [P3]^2)")
    return ELEMENTS[value]
