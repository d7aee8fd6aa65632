"""Geometrically exact nonlinear Naghdi shell of the flat strip (dolfinx 0.5.2).

Formulation (the pattern of FEniCSx-Shells' demo "nonlinear Naghdi clamped semicylinder",
written here for a flat reference configuration and dolfinx 0.5.2):

* Unknowns: displacement u (3 components) of the mid-surface phi = phi0 + u, phi0 = (x, y, 0),
  and the director's rotation from the reference normal e3 as an in-plane rotation vector,
  omega = (-theta1, theta2, 0) (rotation about the axis omega by the angle r = |theta|):

      d(theta) = (sinc(r) th2, -sinc(r) th1, cos r),   sinc(r) = sin(r)/r,

  a unit vector for every theta, singular only at r = pi (a director turned upside down). The
  two-angle form of the FEniCSx-Shells demo, d = (sin th2 cos th1, -sin th1, cos th2 cos th1),
  is singular at th1 = +-pi/2, a director along y: the twisted middle of the US and S shapes
  turns the normal that far, and Newton stalled there (dW/L ~ 0.36 at W/L = 1/6). Both forms
  agree to second order in theta and exactly when th1 = 0 (the compressed U).
* Strains (F = grad phi, 3 x 2; flat reference: a0 = I, b0 = 0):
  membrane eps = (F^T F - I)/2, bending kappa = -(F^T grad d + grad d^T F)/2, transverse
  shear gamma = F^T d.
* Energy per unit reference area, plane-stress isotropic material (E, nu; lambda' = E nu /
  (1 - nu^2), mu = E / (2 (1 + nu))), shear factor 5/6:

      psi_m = b/2 (lambda' tr(eps)^2 + 2 mu eps:eps)
      psi_b = b^3/24 (lambda' tr(kappa)^2 + 2 mu kappa:kappa)
      psi_s = b/2 * 5/6 mu |gamma|^2

  Pi = int (psi_b + psi_m + psi_s) dA. For nu = 0 the bending part is D/2 |kappa|^2 with
  D = E b^3/12, so a narrow strip bends with EI2 = E W b^3/12 like the rod (paper Eq. 4).
* Material "dep" (ShellParameters(material="dep")): the continuum limit of the DDG plate
  (ddg.models.plate; its hinge and spring energies, Eqs. 11a-b, have no Poisson ratio of their
  own): membrane and shear with nu = 1/3, bending with D = E b^3/12 and nu_b = -1/3,

      psi_b = D/2 (nu_b tr(kappa)^2 + (1 - nu_b) kappa:kappa)

  (Seung-Nelson: bending modulus D, Gaussian modulus -4/3 D). A narrow strip then bends with
  8/9 EI2 and twists with GJ = 8/3 D W, as the DEP does; this is for separating the DEP's
  discretisation error from its modelling difference to the nu = 0 shell of the paper.
* Discretisation (MeshSpec.element, fem_reference.elements): by default u in [P2 + B3]^3
  (quadratic Lagrange enriched by the cubic bubble), theta in [P2]^2 on triangles; "P3": u in
  [P3]^3, theta in [P3]^2. Locking (shear and membrane) is treated by partial selective reduced
  integration (PSRI, Arnold & Brezzi 1997): with alpha = b^2/h^2 per cell (h the cell diameter)

      Pi_h = int psi_b dx_4 + alpha int (psi_m + psi_s) dx_4 + (1 - alpha) int (psi_m + psi_s) dx_2

  (dx_k: Gauss rule exact to degree k; 6 and 3 points; P3 uses degrees 6 and 4, 12 and 6
  points). The FEniCSx-Shells demo puts the bubble on the displacement as here; the bubble keeps
  the reduced-integration part free of spurious modes.
* Observation: displacements are read at the nodes of the Lagrange space of the element's
  degree (P2 or P3; exact there, the cubic bubble vanishing at every P2 node): positions, H_mid
  at the centre vertex, the centerline y = 0, the symmetry defects.
* Units: lengths in units of L (mesh x in [0, 1]) and the modulus scaled so that D = 1; energies
  in J are Pi * E b^3/12, forces in the project's unit E b^3 / L are the residual / 12, and the
  eigenvalues of K v = lambda M v with M = int u.v dA (displacement only, units of L) are
  already lambda_min L^4 / EI2 (see eigen_normalisation below).
* Clamps: at x = 0, u = 0 and theta = 0; at x = L, u = (-dL, dW, 0), theta = 0 (the clamps keep
  their orientation). The clamped edges are exactly the mesh ends: the free length is L.
"""
from __future__ import annotations

import contextlib
import logging
from dataclasses import dataclass

import numpy as np

logging.getLogger("FFCx").setLevel(logging.WARNING)
logging.getLogger("UFL").setLevel(logging.WARNING)
logging.getLogger("root").setLevel(logging.WARNING)


@contextlib.contextmanager
def quiet_form_compiler():
    """Silence INFO records while forms are JIT-compiled: the C build (setuptools' distutils
    logging) configures the root logger at INFO on a form's first compilation, whatever its
    level was set to before."""
    previous = logging.root.manager.disable
    logging.disable(logging.INFO)
    try:
        yield
    finally:
        logging.disable(previous)

import dolfinx  # noqa: E402
import dolfinx.fem.petsc  # noqa: E402,F401
import ufl  # noqa: E402
from dolfinx import fem  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from .elements import ELEMENTS  # noqa: E402
from .mesh import CLAMP_END, CLAMP_START, MeshSpec, create_mesh  # noqa: E402

dolfinx.log.set_log_level(dolfinx.log.LogLevel.WARNING)

#: Shear correction factor of the Reissner-Mindlin/Naghdi shear energy.
SHEAR_FACTOR = 5.0 / 6.0

EIGEN_NORMALISATION = ("lowest eigenvalue of the constrained tangent K v = lambda M v, "
                       "M = (1/W) int u.v dA over the displacement (rotations massless), times L^4/EI2")


#: Materials of ShellParameters, and the DDG plate's effective Poisson ratios (material "dep").
from .materials import MATERIALS  # noqa: E402
DEP_MEMBRANE_POISSON, DEP_BENDING_POISSON = 1.0 / 3.0, -1.0 / 3.0

#: Below this r^2 sinc(r) and cos(r) are evaluated by their Taylor series in r^2 (no sqrt at 0).
SMALL_ROTATION2 = 1e-6


def director(theta):
    """Director d = R(omega) e3 for the in-plane rotation vector omega = (-theta1, theta2, 0):
    (sinc(r) theta2, -sinc(r) theta1, cos r), r = |theta| (Rodrigues; flat reference, R0 = I)."""
    r2 = ufl.dot(theta, theta)
    small = ufl.lt(r2, SMALL_ROTATION2)
    r = ufl.sqrt(ufl.conditional(small, SMALL_ROTATION2, r2))  # the exact branch is used only above it
    sinc = ufl.conditional(small, 1.0 - r2 / 6.0 + r2**2 / 120.0, ufl.sin(r) / r)
    cosine = ufl.conditional(small, 1.0 - r2 / 2.0 + r2**2 / 24.0, ufl.cos(r))
    return ufl.as_vector([sinc * theta[1], -sinc * theta[0], cosine])


@dataclass(frozen=True)
class ShellParameters:
    """Nondimensional shell data: thickness t = b/L, width w = W/L, Poisson ratio nu, and the
    material: "isotropic" (plane stress, nu everywhere) or "dep" (the DDG plate's continuum
    limit: nu = 1/3 in membrane and shear, D = E t^3/12 and nu_b = -1/3 in bending; nu unused)."""

    thickness: float
    width: float
    poisson_ratio: float = 0.0
    material: str = "isotropic"

    def __post_init__(self):
        if self.material not in MATERIALS:
            raise ValueError(f"material = {self.material!r} is not one of {MATERIALS}")

    @property
    def membrane_poisson_ratio(self) -> float:
        return DEP_MEMBRANE_POISSON if self.material == "dep" else self.poisson_ratio

    def bending_moduli(self) -> tuple[float, float]:
        """(lambda_b, 2 mu_b) of psi_b = t^3/24 (lambda_b tr(kappa)^2 + 2 mu_b kappa:kappa)."""
        E = self.young_modulus
        if self.material == "dep":
            return E * DEP_BENDING_POISSON, E * (1.0 - DEP_BENDING_POISSON)
        nu = self.poisson_ratio
        return E * nu / (1.0 - nu**2), E / (1.0 + nu)

    @property
    def young_modulus(self) -> float:
        """E in units of D / L^... chosen so that D = E t^3 / 12 = 1."""
        return 12.0 / self.thickness**3


class NaghdiStrip:
    """The discrete Naghdi strip: spaces, energy, residual, tangent, clamps and observables, with
    the finite element of spec.element (fem_reference.elements.ELEMENTS)."""

    def __init__(self, spec: MeshSpec, params: ShellParameters):
        self.spec, self.params = spec, params
        self.shell_element = ELEMENTS[spec.element]
        self.mesh, self.facet_tags = create_mesh(spec)
        mesh = self.mesh
        cell = mesh.ufl_cell()
        e = self.shell_element
        displacement = ufl.FiniteElement("Lagrange", cell, e.degree)
        if e.bubble:
            displacement = displacement + ufl.FiniteElement("Bubble", cell, e.bubble)
        rotation = ufl.FiniteElement("Lagrange", cell, e.rotation_degree)
        self.element = ufl.MixedElement([ufl.VectorElement(displacement, dim=3), ufl.VectorElement(rotation, dim=2)])
        self.V = fem.FunctionSpace(mesh, self.element)
        self.U, self.u_map = self.V.sub(0).collapse()
        self.T, self.theta_map = self.V.sub(1).collapse()
        self.q = fem.Function(self.V)
        self.n_dof = self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs

        with quiet_form_compiler():
            self._build_forms()
            self._build_clamps()
            self._build_observation_spaces()

    # --- energy ----------------------------------------------------------------------
    def _build_forms(self):
        mesh, p = self.mesh, self.params
        t, nu = p.thickness, p.membrane_poisson_ratio
        E = p.young_modulus
        mu = E / (2.0 * (1.0 + nu))
        lam = E * nu / (1.0 - nu**2)
        lam_b, two_mu_b = p.bending_moduli()
        u, theta = ufl.split(self.q)
        x = ufl.SpatialCoordinate(mesh)
        phi0 = ufl.as_vector([x[0], x[1], 0.0])
        F = ufl.grad(phi0 + u)
        d = director(theta)
        eps = 0.5 * (F.T * F - ufl.Identity(2))
        kappa = -0.5 * (F.T * ufl.grad(d) + ufl.grad(d).T * F)
        gamma = F.T * d

        def quad(e):
            return lam * ufl.tr(e) ** 2 + 2.0 * mu * ufl.inner(e, e)

        psi_m = 0.5 * t * quad(eps)
        psi_b = t**3 / 24.0 * (lam_b * ufl.tr(kappa) ** 2 + two_mu_b * ufl.inner(kappa, kappa))
        psi_s = 0.5 * t * SHEAR_FACTOR * mu * ufl.inner(gamma, gamma)
        dx_f = ufl.Measure("dx", domain=mesh, metadata={"quadrature_degree": self.shell_element.full_degree})
        dx_r = ufl.Measure("dx", domain=mesh, metadata={"quadrature_degree": self.shell_element.reduced_degree})
        h = ufl.CellDiameter(mesh)
        alpha_space = fem.FunctionSpace(mesh, ("DG", 0))
        self.alpha = fem.Function(alpha_space)
        self.alpha.interpolate(fem.Expression(t**2 / h**2, alpha_space.element.interpolation_points()))
        alpha = self.alpha
        energy = psi_b * dx_f + alpha * (psi_m + psi_s) * dx_f + (1.0 - alpha) * (psi_m + psi_s) * dx_r
        self.energy_ufl = energy
        q_test, q_trial = ufl.TestFunction(self.V), ufl.TrialFunction(self.V)
        residual = ufl.derivative(energy, self.q, q_test)
        tangent = ufl.derivative(residual, self.q, q_trial)
        self.energy_form = fem.form(energy)
        self.residual_form = fem.form(residual)
        self.tangent_form = fem.form(tangent)
        u_t, _ = ufl.split(q_trial)
        u_v, _ = ufl.split(q_test)
        self.mass_form = fem.form(ufl.inner(u_t, u_v) * ufl.dx(domain=mesh, metadata={"quadrature_degree": 6}))
        self.membrane_energy_form = fem.form(alpha * psi_m * dx_f + (1.0 - alpha) * psi_m * dx_r)
        self.shear_energy_form = fem.form(alpha * psi_s * dx_f + (1.0 - alpha) * psi_s * dx_r)

    # --- clamps ------------------------------------------------------------------------
    def _build_clamps(self):
        fdim = self.mesh.topology.dim - 1
        start = self.facet_tags.indices[self.facet_tags.values == CLAMP_START]
        end = self.facet_tags.indices[self.facet_tags.values == CLAMP_END]
        V, U, T = self.V, self.U, self.T
        self.u_start, self.u_end = fem.Function(U), fem.Function(U)
        self.theta_zero = fem.Function(T)
        dofs_u0 = fem.locate_dofs_topological((V.sub(0), U), fdim, start)
        dofs_u1 = fem.locate_dofs_topological((V.sub(0), U), fdim, end)
        dofs_t0 = fem.locate_dofs_topological((V.sub(1), T), fdim, start)
        dofs_t1 = fem.locate_dofs_topological((V.sub(1), T), fdim, end)
        self.bcs = [fem.dirichletbc(self.u_start, dofs_u0, V.sub(0)), fem.dirichletbc(self.u_end, dofs_u1, V.sub(0)),
                    fem.dirichletbc(self.theta_zero, dofs_t0, V.sub(1)),
                    fem.dirichletbc(self.theta_zero, dofs_t1, V.sub(1))]
        # mixed-space dofs of each displacement component on the moving clamp (for the reaction)
        self.end_component_dofs = []
        for k in range(3):
            Uk, map_k = V.sub(0).sub(k).collapse()
            dofs = fem.locate_dofs_topological((V.sub(0).sub(k), Uk), fdim, end)[0]
            self.end_component_dofs.append(np.asarray(dofs, dtype=np.int32))
        constrained = np.zeros(self.n_dof, dtype=bool)
        for bc in self.bcs:
            constrained[bc.dof_indices()[0]] = True
        self.free = ~constrained

    def set_clamp(self, compression: float, shear: float) -> None:
        """Moving clamp at x = L translated by (-compression, shear, 0), in units of L."""
        value = np.array([-compression, shear, 0.0])
        self.u_end.interpolate(lambda x: np.outer(value, np.ones(x.shape[1])))
        self.clamp = (float(compression), float(shear))

    # --- observation -------------------------------------------------------------------
    def _build_observation_spaces(self):
        from scipy.spatial import cKDTree

        mesh = self.mesh
        # the nodes the displacement is read at: Lagrange of the element's degree (P2 or P3)
        self.nodal = fem.VectorFunctionSpace(mesh, ("Lagrange", self.shell_element.degree), dim=3)
        self.P1 = fem.VectorFunctionSpace(mesh, ("Lagrange", 1), dim=3)
        self.P1_theta = fem.VectorFunctionSpace(mesh, ("Lagrange", 1), dim=2)
        u, theta = ufl.split(self.q)
        self._u_expr = fem.Expression(u, self.nodal.element.interpolation_points())
        self.u_nodal = fem.Function(self.nodal)
        self.u1 = fem.Function(self.P1, name="displacement")
        self.theta1 = fem.Function(self.P1_theta, name="rotation")
        self._theta_expr = fem.Expression(theta, self.P1_theta.element.interpolation_points())
        X = self.nodal.tabulate_dof_coordinates()[:, :2]
        self.nodes_ref = X
        tree = cKDTree(X)
        dist, partner = tree.query(np.column_stack([1.0 - X[:, 0], -X[:, 1]]))
        assert dist.max() < 1e-9, "displacement nodes are not half-turn symmetric"
        self.partner = partner
        dist, mirror = tree.query(np.column_stack([X[:, 0], -X[:, 1]]))
        assert dist.max() < 1e-9
        self.mirror = mirror
        dist, centre = tree.query([0.5, 0.0])
        assert dist < 1e-12, "no displacement node at the centre"
        self.centre_node = int(centre)
        line = np.flatnonzero(np.abs(X[:, 1]) < 1e-12)
        self.centerline_nodes = line[np.argsort(X[line, 0])]
        # P1 vertices and edges / facet-adjacent cells for the resolution indicators
        P1 = self.P1
        self.vertices_ref = P1.tabulate_dof_coordinates()[:, :2]
        tdim = mesh.topology.dim
        mesh.topology.create_connectivity(tdim, 0)
        mesh.topology.create_connectivity(tdim - 1, tdim)
        mesh.topology.create_connectivity(tdim - 1, 0)
        dm = P1.dofmap.list.array.reshape(-1, 3)
        self.cell_vertices = dm
        f2c = mesh.topology.connectivity(tdim - 1, tdim)
        pairs = [f2c.links(f) for f in range(mesh.topology.index_map(tdim - 1).size_local)]
        self.facet_cell_pairs = np.array([p for p in pairs if len(p) == 2], dtype=np.int32)
        edges = np.concatenate([dm[:, [0, 1]], dm[:, [1, 2]], dm[:, [2, 0]]])
        self.edges = np.unique(np.sort(edges, axis=1), axis=0)

    def displacement_nodes(self) -> np.ndarray:
        """(n, 3) displacement at the nodes of self.nodal (P2: exact, the bubble vanishes on edges;
        P3: the element's own nodes), units of L."""
        self.u_nodal.interpolate(self._u_expr)
        return self.u_nodal.x.array.reshape(-1, 3).copy()

    def positions(self) -> np.ndarray:
        u = self.displacement_nodes()
        return np.column_stack([self.nodes_ref, np.zeros(len(u))]) + u

    def energy(self) -> float:
        """Pi in units of D (multiply by E b^3 / 12 for J)."""
        return float(fem.assemble_scalar(self.energy_form))

    def membrane_energy(self) -> float:
        """The membrane part of Pi (its PSRI mix, as in the energy), units of D."""
        return float(fem.assemble_scalar(self.membrane_energy_form))

    def clamp_reaction(self) -> np.ndarray:
        """Force the moving clamp applies to the strip, units of D / L (sum of the residual over
        the clamp's displacement DOFs: virtual work of a rigid clamp translation)."""
        b = fem.petsc.assemble_vector(self.residual_form)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        arr = b.getArray(readonly=True)
        force = np.array([arr[d].sum() for d in self.end_component_dofs])
        b.destroy()
        return force

    def symmetry_defects(self, positions: np.ndarray) -> tuple[float, float]:
        """Largest deviation (units of L) from the half turn about the vertical axis through c
        (U) and from the point reflection through c (S), c midway between the clamp points."""
        compression, shear = self.clamp
        c = np.array([0.5 * (1.0 - compression), 0.5 * shear, 0.0])
        b = positions[self.partner]
        half_turn = np.column_stack([2 * c[0] - b[:, 0], 2 * c[1] - b[:, 1], b[:, 2]])
        point = 2 * c - b
        return (float(np.max(np.linalg.norm(positions - half_turn, axis=1))),
                float(np.max(np.linalg.norm(positions - point, axis=1))))

    def resolution_indicators(self) -> dict:
        """max_turn_angle_deg: largest angle between the normals of neighbouring (P1) triangles;
        max_strain: largest relative change of length of a mesh edge (vertex positions)."""
        self.u1.interpolate(self.u_nodal)
        x = np.column_stack([self.vertices_ref, np.zeros(len(self.vertices_ref))]) + self.u1.x.array.reshape(-1, 3)
        tri = x[self.cell_vertices]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        n /= np.linalg.norm(n, axis=1)[:, None]
        a, b = n[self.facet_cell_pairs[:, 0]], n[self.facet_cell_pairs[:, 1]]
        angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0)))
        xr = np.column_stack([self.vertices_ref, np.zeros(len(self.vertices_ref))])
        e = self.edges
        strain = np.linalg.norm(x[e[:, 1]] - x[e[:, 0]], axis=1) / np.linalg.norm(xr[e[:, 1]] - xr[e[:, 0]], axis=1) - 1
        return {"max_turn_angle_deg": float(angle.max()), "max_strain": float(np.abs(strain).max())}

    def update_output_fields(self) -> None:
        self.u1.interpolate(self.u_nodal)
        self.theta1.interpolate(self._theta_expr)

    # --- state ------------------------------------------------------------------------------
    def get_state(self) -> np.ndarray:
        return self.q.x.array.copy()

    def set_state(self, values: np.ndarray) -> None:
        self.q.x.array[:] = values
        self.q.x.scatter_forward()

    def inextensible_guess(self, compression: float, amplitude_sign: float = 1.0) -> None:
        """First clamped buckling mode w = A (1 - cos 2 pi x) with A such that the centerline is
        inextensible and spans 1 - compression (x-displacement from dX/ds = sqrt(1 - w'^2)),
        director tilted with the slope; u is interpolated at the P2 nodes and L2-projected onto
        [P2 + B3]^3, or interpolated in [P3]^3. (Forms assembled on the collapsed subspace
        V.sub(0).collapse() of the mixed P3 space are wrong in dolfinx 0.5.2: an L2 projection
        there missed the interpolated guess by 0.018 L at the nodes, 12 x 4 elements, while
        interpolation into it and forms on the mixed space agree with a plain P3 space.)"""
        from scipy.integrate import cumulative_trapezoid
        from scipy.optimize import brentq

        s = np.linspace(0.0, 1.0, 4001)
        k = 2.0 * np.pi

        def chord(A):
            slope = np.clip(A * k * np.sin(k * s), -1.0, 1.0)
            return np.trapz(np.sqrt(1.0 - slope**2), s)

        if compression >= 1.0 - chord(1.0 / k) - 1e-9:
            raise ValueError(f"the cosine mode cannot span 1 - {compression:g} inextensibly")
        A = brentq(lambda a: chord(a) - (1.0 - compression), 0.0, 1.0 / k * (1.0 - 1e-12))
        slope = A * k * np.sin(k * s)
        ux = cumulative_trapezoid(np.sqrt(1.0 - slope**2) - 1.0, s, initial=0.0)
        sign = 1.0 if amplitude_sign >= 0 else -1.0

        def u_guess(x):
            return np.vstack([np.interp(x[0], s, ux), np.zeros(x.shape[1]), sign * A * (1.0 - np.cos(k * x[0]))])

        def theta_guess(x):
            return np.vstack([np.zeros(x.shape[1]), -np.arcsin(sign * A * k * np.sin(k * x[0]))])

        if self.shell_element.bubble:  # an enriched space has no nodal interpolation: project
            u_nodes = fem.Function(self.nodal)
            u_nodes.interpolate(u_guess)
            u = self._project(u_nodes, self.U)
        else:  # a Lagrange space: interpolate (see the docstring)
            u = fem.Function(self.U)
            u.interpolate(u_guess)
        theta = fem.Function(self.T)
        theta.interpolate(theta_guess)
        values = self.q.x.array.copy()
        values[self.u_map] = u.x.array
        values[self.theta_map] = theta.x.array
        self.set_state(values)

    def _project(self, source, space):
        """L2 projection of a function onto `space` (MUMPS LU)."""
        w, v = ufl.TrialFunction(space), ufl.TestFunction(space)
        dx = ufl.dx(domain=self.mesh, metadata={"quadrature_degree": 6})
        with quiet_form_compiler():
            problem = fem.petsc.LinearProblem(ufl.inner(w, v) * dx, ufl.inner(source, v) * dx,
                                              petsc_options={"ksp_type": "preonly", "pc_type": "lu",
                                                             "pc_factor_mat_solver_type": "mumps"})
        return problem.solve()


def eigen_normalisation(params: ShellParameters) -> float:
    """Factor from eigenvalues of K v = lambda (int u.v dA) v in the scaled units (D = 1,
    lengths of L) to lambda_SI L^4 / EI2 with the metric M = (1/W) int u.v dA: exactly 1.

    K_SI = (D/L^2) K, M_SI = (L^3/w) M (w = W/L), EI2 = D w L, so lambda_SI L^4/EI2 =
    (D w / L^3) lambda L^4 / (D w L) = lambda."""
    return 1.0
