"""3D large-deformation FE of one sphere in a lattice cell: the solver (issue 62).

The sphere (radius R, centre at the origin) meets rigid frictionless flats (:mod:`.cell_scene`);
the octant x, y, z ≥ 0 is modelled (:mod:`.cell_mesh`), symmetry planes x = 0, y = 0, z = 0.

Kinematics: total Lagrangian, virtual work f_int = ∫ Bᵀ P dV₀, K = ∫ Bᵀ A B dV₀ (Wriggers
2008, §4.2), with the constitutive update of :mod:`.constitutive3d` (shared with the
axisymmetric solver). Quadratic tetrahedra (10 nodes), 4-point Gauss rule.

Contact: exact, as in the axisymmetric solver (:mod:`.contact`). A closed node a of flat k has
n_k · x_a = R − h_k/2 prescribed in a nodal frame Q_a = [n_k, e_j × n_k, e_j] (e_j an axis with
n_k,j = 0; Q_a = I for an axis-aligned flat), an open one carries no force; u = T ū with T the
block-diagonal of the frames, K̄ = Tᵀ K T, r̄ = Tᵀ r. The active set is a primal–dual one updated
inside Newton: close on penetration, release on a tensile reaction; after
:data:`MAX_RELEASES` set changes in an increment nodes are only closed (so the loop ends), and
the largest remaining tensile reaction is reported.

Newton: the consistent tangent of :func:`.constitutive3d.tangent3`, an energy line search
(Crisfield 1991, §9.3: the step α accepted where |du · r̄(u + α du)| ≤ :data:`LINE_SEARCH_RATIO`
|du · r̄(u)|, else a secant step on α, at most :data:`LINE_SEARCH_STEPS` times; halved where an
element inverts), and an increment that does not converge in ``max_iterations`` is cut in half
(at most :data:`MAX_CUTS` times in a row). Linear solves by CHOLMOD (:class:`_Cholesky`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..model.material import Material
from .cell_mesh import Discretisation3, OctantMesh, build_octant_mesh
from .cell_patch import patch_measures
from .cell_scene import SCENES, Scene
from .constitutive3d import PlasticState3, stress_update3, tangent3
from .linsolve import SupernodalCholesky

MAX_RELEASES = 8
LINE_SEARCH_STEPS = 4
#: the line search accepts a step where |du · r̄| has fallen to this fraction of its start
LINE_SEARCH_RATIO = 0.8
MAX_CUTS = 6
#: diagonal shift (fraction of the largest diagonal entry) of a tangent Cholesky refuses
DEFINITE_SHIFT = 1e-6
#: the active set is updated once the free residual is below this fraction of the largest reaction
ACTIVE_SET_TOL = 1e-2


class _Cholesky:
    """K x = b by CHOLMOD's supernodal Cholesky (:class:`.linsolve.SupernodalCholesky`), the
    analysis redone only when the pattern changes; a tangent that is not positive definite is
    factored with its diagonal raised by :data:`DEFINITE_SHIFT` × its largest entry, doubled
    until it is (a damped Newton step, left to the line search)."""

    def __init__(self):
        self._key, self._chol = None, None

    def solve(self, K: sp.csc_matrix, b: np.ndarray) -> np.ndarray:
        U = sp.triu(K, format="csc")
        U.sort_indices()
        key = (U.shape[0], hash(U.indptr.tobytes()), hash(U.indices.tobytes()))
        if key != self._key:
            self._chol, self._key = SupernodalCholesky(U), key
        try:
            self._chol.factor(U)
        except ArithmeticError:
            d = U.diagonal()
            on_diag = np.flatnonzero(U.indices == np.repeat(np.arange(U.shape[0]), np.diff(U.indptr)))
            shift = DEFINITE_SHIFT * float(np.max(np.abs(d)))
            for _ in range(40):
                V = U.copy()
                V.data[on_diag] += shift
                try:
                    self._chol.factor(V)
                    break
                except ArithmeticError:
                    shift *= 4.0
            else:
                raise IncrementFailed("tangent not positive definite even when shifted") from None
        return np.asarray(self._chol.solve(b)).ravel()


@dataclass
class CellResult:
    """Curves of a cell run per converged increment; forces, areas and energies of the whole
    sphere (the octant's × multiplicity or × 8). Per-contact arrays have one column per flat."""

    scene: str
    h: list = field(default_factory=list)  # load approach
    hk: list = field(default_factory=list)  # per-contact approach
    F: list = field(default_factory=list)  # per-contact force (normal reaction)
    A: list = field(default_factory=list)  # per-contact area (cell_patch)
    a: list = field(default_factory=list)  # per-contact √(A/π)
    a_min: list = field(default_factory=list)  # patch extent: smallest sector radius
    a_max: list = field(default_factory=list)  # ... largest
    a_nodes: list = field(default_factory=list)  # largest radius of a closed node
    volume: list = field(default_factory=list)  # solid volume 8 ∫ J dV₀
    density: list = field(default_factory=list)  # relative density (cell_scene)
    work: list = field(default_factory=list)  # external work Σ F_k dh_k (trapezoid)
    stored: list = field(default_factory=list)  # elastic energy ∫ ψ dV₀
    dissipation: list = field(default_factory=list)  # plastic work Σ ∫ σ_f Δγ dV₀
    newton: list = field(default_factory=list)  # Newton iterations per increment
    tension: list = field(default_factory=list)  # largest tensile nodal reaction / largest reaction
    wall_s: float = 0.0
    cpu_s: float = 0.0
    u: np.ndarray | None = None  # displacement of the last converged increment (n_dofs,)
    active: np.ndarray | None = None  # its contact state per node: flat index, −1 open
    n_nodes: int = 0
    n_elements: int = 0

    def arrays(self) -> dict:
        """The curves as numpy arrays."""
        return {k: np.asarray(v) for k, v in self.__dict__.items() if isinstance(v, list)}


class IncrementFailed(RuntimeError):
    """Newton did not converge (even after the increment cuts); ``args[1]``, when given, is the
    :class:`CellResult` of the converged increments."""


class _Contact:
    """Flats, nodal frames and constraint bookkeeping of one mesh and scene."""

    def __init__(self, om: OctantMesh, scene: Scene):
        X, R = om.X, om.radius
        self.X, self.R = X, R
        self.normals = scene.normals
        self.mult = scene.multiplicity
        k = self.normals.shape[0]
        self.Q = np.repeat(np.eye(3)[None], k, axis=0)
        self.ncol = np.zeros(k, dtype=np.int64)
        self.oblique = np.zeros(k, dtype=bool)
        for i, n in enumerate(self.normals):  # a handful of flats, once
            nz = np.flatnonzero(np.abs(n) > 1e-12)
            if nz.size == 1:
                self.ncol[i] = nz[0]
            else:
                e = np.eye(3)[np.flatnonzero(np.abs(n) < 1e-12)[-1]]
                self.Q[i] = np.column_stack([n, np.cross(e, n), e])
                self.oblique[i] = True
        self.on_plane = (np.abs(X) < 1e-12 * R).T  # (n_nodes, 3)
        s = om.sphere
        proj = self.normals @ X[:, s] / R  # (k, n_sphere)
        best = np.argmax(proj, axis=0)
        ok = proj[best, np.arange(s.size)] > 0.5
        self.cand, self.cand_flat = s[ok], best[ok]  # nodes that can meet a flat, and which
        tri = om.sphere_facets
        self.edges = np.unique(np.sort(np.concatenate([tri[[0, 1]], tri[[1, 2]], tri[[2, 0]]], axis=1),
                                       axis=0), axis=1)

    def frames(self, active: np.ndarray):
        """(D, fixed): D = T − I (sparse, None when every frame is I); fixed (n_dofs,) bool of
        the frame dofs held (symmetry planes, the normal of closed nodes)."""
        n_nodes = active.size
        Q = np.broadcast_to(np.eye(3), (n_nodes, 3, 3)).copy()
        act = np.flatnonzero(active >= 0)
        Q[act] = self.Q[active[act]]
        fixed = np.einsum("aj,ajc->ac", self.on_plane.astype(float), np.abs(Q)) > 0.5
        fixed[act, self.ncol[active[act]]] = True
        obl = act[self.oblique[active[act]]]
        D = None
        if obl.size:
            blocks = Q[obl] - np.eye(3)
            rows = (3 * obl[:, None, None] + np.arange(3)[None, :, None]).repeat(3, axis=2)
            cols = (3 * obl[:, None, None] + np.arange(3)[None, None, :]).repeat(3, axis=1)
            D = sp.csr_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(3 * n_nodes,) * 2)
        return D, fixed.ravel()

    def project(self, u: np.ndarray, active: np.ndarray, offsets: np.ndarray) -> np.ndarray:
        """u with every closed node moved along its flat's normal onto the flat."""
        act = np.flatnonzero(active >= 0)
        n = self.normals[active[act]]  # (m, 3)
        x = self.X[:, act].T + u.reshape(-1, 3)[act]
        u = u.copy().reshape(-1, 3)
        u[act] += n * (offsets[active[act]] - np.sum(n * x, axis=1))[:, None]
        return u.ravel()

    def reactions(self, r: np.ndarray, active: np.ndarray) -> np.ndarray:
        """Normal reaction λ_a = −n · r_a of every closed node (0 on open ones)."""
        lam = np.zeros(active.size)
        act = np.flatnonzero(active >= 0)
        lam[act] = -np.sum(self.normals[active[act]] * r.reshape(-1, 3)[act], axis=1)
        return lam

    def penetration(self, u: np.ndarray, offsets: np.ndarray) -> np.ndarray:
        """n · x − offset of every candidate node on its flat (> 0: through it)."""
        x = self.X[:, self.cand] + u.reshape(-1, 3)[self.cand].T
        return np.sum(self.normals[self.cand_flat].T * x, axis=0) - offsets[self.cand_flat]


def _evaluate(disc: Discretisation3, u, state: PlasticState3, material: Material):
    """(F, update, f_int) at u, or None where an element inverts (J ≤ 0)."""
    Fq = disc.deformation_gradient(u)
    if np.any(np.linalg.det(Fq) <= 0):
        return None
    upd = stress_update3(Fq, state.cp_inv, state.eps_p, material)
    return Fq, upd, disc.internal_force(upd.P)


def _increment(disc, con: _Contact, solver, material, state, u, active, offsets, tol, max_iterations):
    """Newton with the primal–dual active set for one increment (module docstring).

    Returns (u, active, update, iterations, tension) or raises :class:`IncrementFailed`."""
    active = active.copy()
    pen = con.penetration(u, offsets)
    close = pen > 0
    active[con.cand[close]] = con.cand_flat[close]
    u = con.project(u, active, offsets)
    ev = _evaluate(disc, u, state, material)
    if ev is None:
        raise IncrementFailed("inverted element at the predictor")
    changes, its = 0, 0
    for _it in range(max_iterations + 2 * MAX_RELEASES + 20):
        Fq, upd, r = ev
        D, fixed = con.frames(active)
        rb = r + D.T @ r if D is not None else r
        free = np.flatnonzero(~fixed)
        lam = con.reactions(r, active)
        scale = max(float(np.max(np.abs(lam))), 1e-300)
        res_free = float(np.max(np.abs(rb[free]))) if free.size else 0.0
        if its > 0 and res_free <= ACTIVE_SET_TOL * scale:  # primal–dual active set, near equilibrium
            pen = con.penetration(u, offsets)
            closing = (pen > 1e-12 * con.R) & (active[con.cand] < 0)
            releasing = (lam < 0) & (changes < MAX_RELEASES)
            if np.any(closing) or np.any(releasing):
                changes += 1
                active[releasing] = -1
                active[con.cand[closing]] = con.cand_flat[closing]
                u = con.project(u, active, offsets)
                ev = _evaluate(disc, u, state, material)
                if ev is None:
                    raise IncrementFailed("inverted element after an active-set change")
                continue
            if res_free <= tol * scale:
                tension = max(0.0, float(-lam.min())) / scale
                return u, active, upd, its, tension
        if its >= max_iterations:
            break
        K = disc.tangent(tangent3(Fq, state, material, upd))
        if D is not None:
            KD = K @ D
            K = K + KD + D.T @ K + D.T @ KD
        K = K.tocsc()
        dub = np.zeros_like(u)
        dub[free] = solver.solve(K[free][:, free], -rb[free])
        du = dub + D @ dub if D is not None else dub
        its += 1
        s0 = float(dub[free] @ rb[free])
        alpha, ev_new = 1.0, None
        for _ls in range(LINE_SEARCH_STEPS + 1):  # energy line search (Crisfield 1991, §9.3)
            trial = _evaluate(disc, u + alpha * du, state, material)
            if trial is None:  # J ≤ 0: halve
                alpha *= 0.5
                continue
            rt = trial[2] + D.T @ trial[2] if D is not None else trial[2]
            s1 = float(dub[free] @ rt[free])
            ev_new = (alpha, trial)
            if abs(s1) <= LINE_SEARCH_RATIO * abs(s0) or s0 >= 0 or _ls == LINE_SEARCH_STEPS:
                break
            # secant root of s(α) = du · r̄(u + α du) between 0 and α, kept within [0.1, 1] α
            alpha = alpha * float(np.clip(s0 / (s0 - s1), 0.1, 1.0)) if s1 != s0 else 0.5 * alpha
        if ev_new is None:
            raise IncrementFailed("every line-search step inverts an element")
        u = u + ev_new[0] * du
        ev = ev_new[1]
    raise IncrementFailed(f"Newton did not converge in {max_iterations} iterations")


def run_cell(scene: Scene | str, material: Material, h_values, density: float = 1.0,
             radius: float = 1.0, mesh_options: dict | None = None, tol: float = 1e-4,
             max_iterations: int = 25, progress=None, mesh: OctantMesh | None = None,
             stop=None) -> CellResult:
    """Load the sphere of ``scene`` through the load approaches ``h_values`` (increasing).

    Each increment starts from the secant extrapolation of the last two converged ones; an
    increment that fails is cut in half (at most :data:`MAX_CUTS` times in a row) and the
    run stops with :class:`IncrementFailed` beyond that. ``mesh_options`` go to
    :func:`.cell_mesh.build_octant_mesh` (the poles are the scene's flats). ``stop(result)``,
    called after each increment, ends the run early when it returns True (e.g. a density reached).
    """
    t0, c0 = time.perf_counter(), time.process_time()
    sc = SCENES[scene] if isinstance(scene, str) else scene
    om = mesh if mesh is not None else build_octant_mesh(radius, density, poles=sc.normals,
                                                         **(mesh_options or {}))
    disc = Discretisation3(om)
    con = _Contact(om, sc)
    R = om.radius
    res = CellResult(scene=sc.name, n_nodes=om.X.shape[1], n_elements=disc.n_elements)
    solver = _Cholesky()
    state = PlasticState3.virgin(disc.n_elements * disc.n_qp)
    u = np.zeros(disc.n_dofs)
    active = np.full(om.X.shape[1], -1, dtype=np.int64)
    hist = [(0.0, u.copy())]  # (h, u) of the last two converged increments
    lam_last = np.zeros(len(sc.flats))
    work = dissip = 0.0
    targets = list(np.asarray(h_values, dtype=float))[::-1]
    cuts = 0
    while targets:
        h = targets[-1]
        h_prev = hist[-1][0]
        u_pred = hist[-1][1].copy()
        if len(hist) > 1:
            u_pred += (hist[-1][1] - hist[-2][1]) * (h - h_prev) / (h_prev - hist[-2][0])
        hk = sc.approaches(h)
        offsets = R - 0.5 * hk
        try:
            u_new, act_new, upd, its, tension = _increment(disc, con, solver, material, state, u_pred,
                                                           active, offsets, tol, max_iterations)
        except IncrementFailed as err:
            cuts += 1
            if cuts > MAX_CUTS:
                res.wall_s = time.perf_counter() - t0
                res.cpu_s = time.process_time() - c0
                raise IncrementFailed(f"no convergence at h = {h:g} after {MAX_CUTS} cuts: {err}",
                                      res) from err
            targets.append(0.5 * (h + h_prev))
            continue
        cuts = 0
        targets.pop()
        u, active = u_new, act_new
        Fq = disc.deformation_gradient(u)
        r = disc.internal_force(upd.P)
        lam = con.reactions(r, active)
        lam_k = np.bincount(active[active >= 0], weights=lam[active >= 0], minlength=len(sc.flats))
        hk_prev = sc.approaches(h_prev)
        work += 8.0 * float(np.sum(0.5 * (lam_k + lam_last) * 0.5 * (hk - hk_prev)))
        lam_last = lam_k
        if np.isfinite(material.sigma_y):
            dissip += 8.0 * disc.integrate(material.flow_stress(upd.eps_p) * upd.dgamma)
        state = PlasticState3(upd.cp_inv, upd.eps_p)
        hist = [hist[-1], (h, u.copy())]
        x = om.X + u.reshape(-1, 3).T
        patches = [patch_measures(x, con.cand[con.cand_flat == k], con.edges, active == k,
                                  sc.normals[k], offsets[k], sc.multiplicity[k])
                   for k in range(len(sc.flats))]  # a few contacts, once per increment
        vol = 8.0 * disc.integrate(np.linalg.det(Fq))
        res.h.append(float(h))
        res.hk.append(hk)
        res.F.append(lam_k * sc.multiplicity)
        for key in ("A", "a", "a_min", "a_max", "a_nodes"):
            getattr(res, key).append(np.array([p[key] for p in patches]))
        res.volume.append(vol)
        res.density.append(sc.density(vol, h, R))
        res.work.append(work)
        res.stored.append(8.0 * disc.integrate(upd.psi))
        res.dissipation.append(dissip)
        res.newton.append(its)
        res.tension.append(tension)
        res.u, res.active = u, active
        if progress is not None:
            progress(res)
        if stop is not None and stop(res):
            break
    res.wall_s = time.perf_counter() - t0
    res.cpu_s = time.process_time() - c0
    return res


def run_two_flats(material: Material, h_values, density: float = 1.0, radius: float = 1.0,
                  **kwargs) -> CellResult:
    """The sphere between two rigid plates (h: the change of their separation): each half is a
    hemisphere on a flat with approach h/2, F(h) = F_ax(h/2) of the axisymmetric flat scene."""
    return run_cell("two-flats", material, h_values, density, radius, **kwargs)
