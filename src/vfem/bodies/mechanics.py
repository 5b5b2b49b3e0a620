"""The mechanics behind a body: how it answers the contact forces it carries.

One interface, :class:`BodyMechanics`, two implementations:

* :class:`LinearMechanics` — small kinematics: the superposition of the body's unit solutions and
  ``K^-1 f_contact`` through its one factorization (:class:`~vfem.bodies.Body`); its flexibility
  on the contact dofs is constant (the inverse of the Schur complement on them);
* :class:`LargeMechanics` — large kinematics (thesis Ch. 2-3): the hyperelastic body of
  :mod:`vfem.nonlinear`, equilibrated under given contact forces, linearised at its trial state
  (Newton's system and the tangent flexibility on the contact dofs, :class:`Linearization`),
  moved, committed or discarded step by step.

A formulation that corrects the bodies by Newton's method (contact's large kinematics) asks every
body for its trial displacement, its linearisation and its equilibration; a linear body answers
None to each (its displacement is the contact state's), so the formulation never asks which
kind of body it has: a body with another response (a plastic one, say) is a third
implementation of the same questions.

:class:`~vfem.bodies.Body` keeps the description (mesh, material, supports, loads) and its
assembly, and hands every kinematics-dependent question to its ``mechanics``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Protocol

import numpy as np
import scipy.sparse as sp

from ..errors import AnalysisError
from ..linalg import factorize
from ..nonlinear import NonlinearBody
from .loads import boundary_dofs
from .stresses import cauchy_stress, small_strain_stress

log = logging.getLogger(__name__)


class BodyMechanics(Protocol):
    """What the solver and the contact formulations ask of a body, whatever its kinematics."""

    def displacement(self, load_factor: float, platen_displacement: float,
                     contact_force: np.ndarray) -> np.ndarray:
        """The full displacement (ndofs) under the loads at ``load_factor``, the platen at
        ``platen_displacement`` and the nodal ``contact_force`` (ndofs)."""

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        """The internal nodal forces (ndofs) at displacement ``u`` (reactions read them)."""

    def stress(self, u: np.ndarray) -> dict[str, np.ndarray]:
        """Element-average stresses of displacement ``u``."""

    def commit(self) -> None:
        """A step converged: keep its state."""

    def discard(self) -> None:
        """A step failed: go back to the last converged state."""

    def saved_state(self) -> dict[str, np.ndarray]:
        """The converged state as arrays (checkpoints, step cutting)."""

    def restore_state(self, state: dict[str, np.ndarray]) -> None:
        """Put back a state from :meth:`saved_state` exactly."""

    # -- what a formulation that corrects the bodies by Newton's method asks (contact's large
    # kinematics, vfem.contact.formulations.large); a body whose response is linear in its
    # contact forces answers None: its displacement is the contact state's

    def trial_displacement(self) -> np.ndarray | None:
        """The displacement (ndofs) of the body's own trial state, or None where the body has
        none (its displacement follows from the contact forces, :meth:`displacement`)."""

    def linearize(self, load_factor: float, platen_displacement: float,
                  contact_force: np.ndarray, condensed_dofs: np.ndarray,
                  candidate_dofs: np.ndarray, backend: str | None = None
                  ) -> Linearization | None:
        """Newton's system at the trial state under the contact forces held; None where the
        body's response is linear (nothing to correct but the contact forces)."""

    def equilibrate(self, load_factor: float, platen_displacement: float,
                    contact_force: np.ndarray) -> np.ndarray | None:
        """Equilibrate the trial state under the given contact forces; None where the body is
        always in equilibrium with them."""

    def move(self, correction: np.ndarray) -> None:
        """Add a Newton correction (ndofs) to the trial state; nothing where there is none."""


class LinearMechanics:
    """Small kinematics: the body's response is linear, its state the contact state's (the
    contact forces, platen motion and load factor), so there is nothing to commit or save."""

    def __init__(self, body):
        self.body = body

    def displacement(self, load_factor: float, platen_displacement: float,
                     contact_force: np.ndarray) -> np.ndarray:
        b = self.body
        return (b.load_displacement(load_factor) + platen_displacement * b.u_platen
                + b.response(contact_force))

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        return self.body.K @ u

    def stress(self, u: np.ndarray) -> dict[str, np.ndarray]:
        """Element-average small-strain stresses
        (:func:`~vfem.bodies.stresses.small_strain_stress`)."""
        return small_strain_stress(self.body, u)

    def commit(self) -> None:
        pass

    def discard(self) -> None:
        pass

    def saved_state(self) -> dict[str, np.ndarray]:
        return {}

    def restore_state(self, state: dict[str, np.ndarray]) -> None:
        pass

    def trial_displacement(self) -> None:
        return None  # the contact state's: load, platen and contact force superposed

    def linearize(self, load_factor: float, platen_displacement: float,
                  contact_force: np.ndarray, condensed_dofs: np.ndarray,
                  candidate_dofs: np.ndarray, backend: str | None = None) -> None:
        return None  # linear: its flexibility is the condensed one, constant

    def equilibrate(self, load_factor: float, platen_displacement: float,
                    contact_force: np.ndarray) -> None:
        return None  # always in equilibrium with its contact forces

    def move(self, correction: np.ndarray) -> None:
        pass  # no trial state: its displacement is the contact state's


def mechanics_for(body, fixed: dict[int, float]) -> BodyMechanics:
    """The mechanics of an assembled body: Newton's (:class:`LargeMechanics`) where its response
    is nonlinear (:attr:`~vfem.bodies.Body.iterates`), else the linear superposition: how
    :func:`~vfem.bodies.condensation.setup` chooses (a body only assembled, a baseline's, and a
    body on another MPI rank are linear, :attr:`Body.mechanics`, ``parallel``). ``fixed``: the
    prescribed value of every constrained dof (:func:`~vfem.bodies.loads.constraints`)."""
    return LargeMechanics(body, fixed) if body.iterates else LinearMechanics(body)


#: A large body whose tangent is not positive definite takes its flexibility by
#: back-substitutions, this many candidate dofs at a time.
FALLBACK_COLUMNS = 128


def yielded_points(mechanics) -> int | None:
    """The quadrature points of a body whose material shows a ``yielded`` flag (a plastic one,
    :mod:`vfem.materials.plastic`) where it is set, in its converged state; None for a body
    whose material shows none."""
    nonlinear = getattr(mechanics, "nonlinear", None)
    shown = getattr(getattr(nonlinear, "material", None), "fields", None)
    if shown is None:
        return None
    flag = shown(nonlinear.material_state).get("yielded")
    return None if flag is None else int(np.count_nonzero(flag))


class LargeMechanics:
    """Large kinematics (see the module docstring)."""

    def __init__(self, body, fixed: dict[int, float]):
        """The hyperelastic body behind a large-kinematics body (:mod:`vfem.nonlinear`).

        Its supports and prescribed displacements are prescribed dofs scaled by the load factor,
        its tractions dead nodal forces (per undeformed length, as for small kinematics), and a
        platen's dofs follow the platen displacement the contact iteration sets. The linear
        quantities set up above are the tangent ones at rest, which is where the first step
        starts from.
        """
        self.body = body
        material = body.material.law(body.law, body.kinematics)  # the law it evaluates
        nl = NonlinearBody(body.mesh, material, formulation=body.kinematics,
                           order=body.order, name=f"body {body.name!r}",
                           axisymmetric=body.section.space == "axisymmetric")
        dofs = np.array(sorted(fixed), dtype=int)
        if len(dofs):
            nl.prescribe(dofs, np.array([fixed[d] for d in dofs.tolist()]))
        for pd in body.prescribed:  # later ones win, as in loads.constraints
            dofs = boundary_dofs(body, pd.boundary, pd.component)
            nl.prescribe(dofs, _ramp(pd, len(dofs)))
        self._platen_value = 0.0
        self._tangent_analysis = None  # the last tangent's factorization (its ordering reused)
        self._free_map = None  # where the tangent's entries go in its free block
        if len(body.platen_dofs):
            nl.prescribe(body.platen_dofs,
                         lambda lf: np.full(len(body.platen_dofs), self._platen_value))
        nl.add_nodal_forces(np.arange(body.ndofs), body.f_load)
        if any(tr.amplitude is not None for tr in body.tractions):  # not proportional
            nl.set_load_history(body.applied_load)
        self.nonlinear = nl
        self._equilibrated: tuple | None = None
        #: over MPI ranks (:func:`vfem.parallel.set_up_bodies`): the ranks and this body's
        #: index. Every rank keeps the body's state (its trial and converged displacements
        #: and material state, which the contact iteration reads on every rank); its owner
        #: alone factorizes its tangent and solves with it, and hands the others what comes
        #: of that (:meth:`_shared_system`, :meth:`equilibrate`)
        self.ranks = None
        self.index = -1

    def _parallel(self) -> bool:
        return self.ranks is not None and self.ranks.parallel

    def equilibrate(self, load_factor: float, platen_displacement: float,
                    contact_force: np.ndarray) -> np.ndarray:
        """The equilibrium displacement (ndofs) under the loads at
        ``load_factor``, the platen at ``platen_displacement`` and the nodal ``contact_force``
        (a trial state of the step, see :meth:`commit_step`). Repeated calls with the same
        arguments cost nothing. Over MPI ranks its owner solves and the others take its trial
        state (:meth:`~vfem.nonlinear.NonlinearBody.adopt`)."""
        f = np.asarray(contact_force, dtype=float)
        key = (float(load_factor), float(platen_displacement), f.tobytes())
        if self._equilibrated != key:
            self._platen_value = float(platen_displacement)
            if self._parallel():
                nl = self.nonlinear

                def solve() -> tuple:
                    record = nl.equilibrate(load_factor, f)
                    return nl.trial_displacement() - nl.displacement, record

                delta, record = self.ranks.share(self.index, solve)
                if not self.ranks.mine(self.index):
                    nl.adopt(delta, load_factor, record)
            else:
                self.nonlinear.equilibrate(load_factor, f)
            self._equilibrated = key
        return self.nonlinear.trial_displacement()

    def linearize(self, load_factor: float, platen_displacement: float,
                  contact_force: np.ndarray, condensed_dofs: np.ndarray,
                  candidate_dofs: np.ndarray, backend: str | None = None) -> Linearization:
        """Newton's system at the trial state under the loads at
        ``load_factor``, the platen at ``platen_displacement`` and the nodal ``contact_force``
        (held), factorized once (see :class:`Linearization`). Move the trial state with
        :meth:`move`.

        The residual is evaluated at once; the tangent, its factorization and what comes from
        them when first asked for (:class:`Linearization`): the contact iteration's last check
        of a step, which finds the bodies in equilibrium, needs no more (in the sliding example
        one linearisation in six)."""
        self._platen_value = float(platen_displacement)
        self._equilibrated = None
        R, ref, tangent, D, pending = self.nonlinear.residual(load_factor, contact_force)
        free = np.setdiff1d(np.arange(self.body.ndofs), D)
        met = float(np.abs(pending).max(initial=0.0)) <= 1e-13 * self.nonlinear.length

        def system() -> dict:
            K = tangent()
            K_ff = self._free_block(K, free)
            # the condensed dofs among the free ones: their block of the inverse tangent is
            # the inverse of its Schur complement, from the factorization (as for the linear
            # body)
            pos = np.searchsorted(free, condensed_dofs)
            held = free[np.minimum(pos, len(free) - 1)] == condensed_dofs
            factor, step = _tangent_factorization(K_ff, pos[held], free // self.body.dim,
                                                  -R[free] - K[free] @ pending, backend,
                                                  self.body.name, self._tangent_analysis)
            self._tangent_analysis = factor if factor.trailing_inverse is not None else None

            def solve(f: np.ndarray) -> np.ndarray:
                out = np.zeros((self.body.ndofs,) + f.shape[1:])
                out[free] = factor.solve(f[free])
                return out

            correction = pending.copy()
            correction[free] = step
            # flexibility rows of the condensed dofs for the candidate dofs (supports kept); the
            # candidate dofs are the first of them (ContactSurface.condensed_dofs)
            nc2 = len(candidate_dofs)
            flexibility = np.zeros((len(condensed_dofs), nc2))
            if factor.trailing_inverse is not None:
                rows = np.flatnonzero(held)
                cols = rows[rows < nc2]
                flexibility[np.ix_(rows, cols)] = factor.trailing_inverse[:, : len(cols)]
            else:  # an indefinite tangent: one back-substitution per candidate dof, in
                # blocks of columns (all at once held several ndofs x 2 nc arrays: 2.4 GB at
                # the peak of total-Lagrangian Hertz at 119k dofs)
                pos = np.searchsorted(free, candidate_dofs)
                cols = np.flatnonzero(free[np.minimum(pos, len(free) - 1)] == candidate_dofs)
                for start in range(0, len(cols), FALLBACK_COLUMNS):
                    block = cols[start:start + FALLBACK_COLUMNS]
                    unit = np.zeros((self.body.ndofs, len(block)))
                    unit[candidate_dofs[block], np.arange(len(block))] = 1.0
                    flexibility[:, block] = solve(unit)[condensed_dofs]
            platen_motion = np.zeros(self.body.ndofs)
            stiffness = reaction = 0.0
            P = self.body.platen_dofs
            if len(P):
                platen_motion[P] = 1.0
                platen_motion[free] = factor.solve(-(K[free][:, P] @ np.ones(len(P))))
                stiffness = _platen_stiffness(K, platen_motion, P)
                reaction = float((R + K @ correction)[P].sum())
            return {"correction": correction, "flexibility": flexibility,
                    "platen_motion": platen_motion, "platen_stiffness": stiffness,
                    "platen_reaction": reaction, "solve": solve}

        if self._parallel():
            system = self._shared_system(system)
        return Linearization(float(np.linalg.norm(R[free])), ref, met, system)

    def _shared_system(self, system: Callable[[], dict]) -> Callable[[], dict]:
        """Over MPI ranks: ``system`` (the tangent factorized, the correction, the
        flexibility) computed on the body's owner alone, its arrays sent to every rank, and a
        ``solve`` that solves on the owner (every rank asks it the same at the same point of
        the same iteration, as :class:`~vfem.parallel.SharedFactor`'s)."""
        ranks, index = self.ranks, self.index
        kept: dict = {}

        def arrays() -> dict:
            out = system()
            kept["solve"] = out.pop("solve")
            return out

        def shared() -> dict:
            out = kept.pop("arrays") if "arrays" in kept else ranks.share(index, arrays)
            owner_solve = kept.get("solve")
            out["solve"] = lambda f: ranks.share(index, lambda: owner_solve(f))
            return out

        # (every body's owner at once: :func:`prefetch`)
        shared.index, shared.owner_arrays, shared.kept = index, arrays, kept
        return shared

    def _free_block(self, K: sp.csr_matrix, free: np.ndarray) -> sp.csc_matrix:
        """``K[free][:, free]`` as CSC. The tangent's pattern and the free dofs stay from one
        iteration to the next, so where each stored entry goes is found once (by slicing a
        matrix that holds each entry's number) and reused while they stay."""
        key = (K.shape, K.nnz, free.tobytes())
        if self._free_map is None or self._free_map[0] != key or not (
                np.array_equal(self._free_map[1], K.indptr)
                and np.array_equal(self._free_map[2], K.indices)):
            numbered = sp.csr_matrix((np.arange(1, K.nnz + 1, dtype=float), K.indices,
                                      K.indptr), shape=K.shape)
            block = numbered[free][:, free].tocsc()
            block.sort_indices()
            self._free_map = (key, K.indptr.copy(), K.indices.copy(),
                              np.rint(block.data).astype(np.int64) - 1, block.indices,
                              block.indptr, block.shape)
        _, _, _, pick, indices, indptr, shape = self._free_map
        return sp.csc_matrix((K.data[pick], indices, indptr), shape=shape)

    def move(self, correction: np.ndarray) -> None:
        """Add ``correction`` (ndofs) to the trial displacement.

        Raises:
            AnalysisError: an element would turn inside out; the trial state is unchanged.
        """
        self.nonlinear.move(correction)
        self._equilibrated = None

    def trial_displacement(self) -> np.ndarray:
        """The displacement (ndofs) of the trial state (the converged one without a trial)."""
        return self.nonlinear.trial_displacement()

    def commit(self) -> None:
        """A step converged: its trial state becomes the start of the next."""
        self.nonlinear.accept()
        self._equilibrated = None

    def discard(self) -> None:
        """A step failed: go back to the last converged state."""
        self.nonlinear.discard()
        self._equilibrated = None

    def saved_state(self) -> dict[str, np.ndarray]:
        """The converged state as arrays."""
        return {**self.nonlinear.saved_state(), "platen_value": np.array(self._platen_value)}

    def restore_state(self, state: dict[str, np.ndarray]) -> None:
        """Put back a state from :meth:`saved_state` exactly (step cutting, ``--resume``)."""
        self.nonlinear.restore_state(state)
        self._platen_value = float(state["platen_value"])
        self._equilibrated = None

    def displacement(self, load_factor: float, platen_displacement: float,
                     contact_force: np.ndarray) -> np.ndarray:
        """The equilibrium displacement (ndofs) for the given state (a copy)."""
        return self.equilibrate(load_factor, platen_displacement, contact_force).copy()

    def internal_force(self, u: np.ndarray) -> np.ndarray:
        """The internal nodal forces (ndofs) at displacement ``u``."""
        return self.nonlinear.internal_force_at(u)

    def stress(self, u: np.ndarray) -> dict[str, np.ndarray]:
        """Element-average Cauchy stresses in the deformed configuration
        (:func:`~vfem.bodies.stresses.cauchy_stress`)."""
        return cauchy_stress(self.nonlinear, u)


class Linearization:
    """Newton's system of a large-kinematics body at its trial state (:meth:`Body.linearize`).

    ``residual``, ``reference`` and ``prescribed_met`` are there at once; the others are
    computed together (the tangent assembled and factorized) when one of them is first read.

    Attributes:
        residual: norm of the out-of-balance force ``f_int - f_ext`` on the free dofs.
        reference: the force it is measured against (:class:`vfem.nonlinear.NewtonStep`).
        prescribed_met: whether the prescribed displacements (the platen's included) have
            their values (else ``correction`` applies what they lack).
        correction: (ndofs) Newton's correction with the contact forces held, the prescribed
            displacements' increments included.
        flexibility: (condensed, candidate) the tangent flexibility rows of the condensed dofs for
            the candidate dofs (supports kept): the inverse of the tangent's Schur complement on
            the condensed dofs, from its factorization (:func:`_tangent_factorization`).
        platen_motion: (ndofs) the motion per unit motion of the platen (1 on its dofs).
        platen_stiffness: the platen's reaction per unit platen motion.
        platen_reaction: the platen's reaction after ``correction``, linearised.
        solve: the tangent flexibility applied to nodal forces (ndofs, or ndofs x k): the
            displacements (zero on the fixed dofs).
    """

    _LAZY = ("correction", "flexibility", "platen_motion", "platen_stiffness",
             "platen_reaction", "solve")

    def __init__(self, residual: float, reference: float, prescribed_met: bool,
                 system: Callable[[], dict]):
        self.residual = residual
        self.reference = reference
        self.prescribed_met = prescribed_met
        self._system = system

    def __getattr__(self, name: str):
        # only reached for attributes not yet set: the lazy ones, computed together once
        if name in Linearization._LAZY and "_system" in self.__dict__:
            self.__dict__.update(self.__dict__.pop("_system")())
            return self.__dict__[name]
        raise AttributeError(name)


def prefetch(ranks, linearizations: list) -> None:
    """Over MPI ranks, the linearisations (:class:`Linearization`, of bodies whose tangent
    is factorized on their owner, :meth:`LargeMechanics._shared_system`) not yet computed,
    each on its owner, all owners at once (:meth:`~vfem.parallel.Ranks.map`), and every rank
    given their arrays: what reading them one by one would do with the owners in turn."""
    pending = {}
    for lin in linearizations:
        system = None if lin is None else lin.__dict__.get("_system")
        if system is not None and hasattr(system, "owner_arrays"):
            pending[system.index] = system
    if not pending or not getattr(ranks, "parallel", False):
        return
    got = ranks.map(sorted(pending), lambda i: pending[i].owner_arrays())
    for i, system in pending.items():
        system.kept["arrays"] = got[i]


def _tangent_factorization(K_ff, trailing: np.ndarray, groups: np.ndarray, rhs: np.ndarray,
                           backend: str | None, name: str, analysis=None):
    """A large body's tangent on its free dofs, factorized once per linearisation.

    A tangent is positive definite unless the body is near buckling (geometric stiffness under
    compression). It is first factorized as such with the ``trailing`` (tracked) dofs eliminated
    last, which also yields the inverse tangent on them (``trailing_inverse``: the tangent
    flexibility, from the Schur complement, instead of one back-substitution per contact dof).
    Where that fails (not positive definite) or its solve of ``rhs`` is not accurate (SuperLU
    factorizes in that order without pivoting), the tangent is factorized as indefinite and
    ``trailing_inverse`` is None. Returns the factorization and its solution of ``rhs``.
    ``analysis``: the last iteration's factorization, whose analysis may be taken over
    (:func:`vfem.linalg.factorize`).
    """
    if len(trailing):
        try:
            factor = factorize(K_ff, backend, trailing=trailing, groups=groups,
                               what=f"body {name!r} (tangent)", analysis=analysis)
            x = factor.solve(rhs)
            scale = max(float(np.abs(rhs).max(initial=0.0)), 1e-300)
            if (factor.trailing_inverse is not None
                    and float(np.abs(K_ff @ x - rhs).max(initial=0.0)) <= 1e-10 * scale):
                return factor, x
        except AnalysisError as exc:
            log.debug("body %r: tangent not positive definite (%s); factorized as indefinite",
                      name, exc)
    factor = factorize(K_ff, backend, spd=False, what=f"body {name!r} (tangent)")
    factor.trailing_inverse = None
    return factor, factor.solve(rhs)


def _platen_stiffness(K, motion: np.ndarray, platen_dofs: np.ndarray) -> float:
    """The platen's reaction per unit platen motion (``motion``: the body's response to it).

    A body that only contact holds moves rigidly with its platen: zero up to round-off, which
    is cleaned to exactly zero (the platen's equations then know nothing else holds the body).
    """
    stiffness = float((K @ motion)[platen_dofs].sum())
    scale = float(K.diagonal()[platen_dofs].sum())
    return stiffness if abs(stiffness) > 1e-9 * scale else 0.0


def _ramp(pd, n: int):
    """The values of ``n`` dofs under ``pd`` as a function of the load factor."""
    return lambda load_factor: np.full(n, pd.at(load_factor))


__all__ = ["BodyMechanics", "LargeMechanics", "LinearMechanics", "Linearization", "prefetch"]
