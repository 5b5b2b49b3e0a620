"""Which route the contact correction takes by predicted time (issue 40, item 3): the dense one,
each body condensed to its contact dofs and the pair matrix W formed, or the matrix-free one,
W applied through each body's plain factorization
(:mod:`~vfem.contact.solvers.matrix_free`).

What each route costs beyond the other, predicted from the model before anything is
factorized (seconds on the 2-core machine, PARDISO; the measurements in ``docs/scaling.md``,
section 1, "Choosing"):

* **dense**: each body's Schur complement on its m_b condensed dofs
  (``ContactSurface.condensed_dofs``: the candidates' for the paired variant, which reads no
  rind, as the solver sets them before it asks) formed and inverted, W formed and each contact
  set's block factorized: ``DENSE_CUBE * sum m_b^3 + DENSE_SQUARE * sum m_b^2``, fitted
  (relative least squares) to the flat plates of ``benchmarks/matrix_free.py`` from 3,939 to
  16,371 contact dofs (the two routes' total times' difference, where the matrix-free route's
  own cost is a few percent of it): within 2 % there; 0.16 s predicted against 0.21 s at
  2,064, 0.017 against 0.043 at 732;
* **matrix-free**: each application of W two back-substitutions through every body's factor,
  ``products * (APPLY * sum nnz(L_b) + APPLY_FIXED * bodies)``
  (:func:`vfem.memory.factor_entries`, the plain factor), ``APPLY`` measured 5.1-5.2e-10 s an
  entry an application on the sphere refined once (617 applications, 32.6 s) and on the
  55-division plates (39, 0.75 s), ``APPLY_FIXED`` what an application costs a body besides
  (0.3 ms on the 10-division plates: 77 applications, 0.06 s, of which the factors' entries
  0.01 s); the products are not known before the run: :data:`PRODUCTS_PER_STEP` a step.

The choice is a prediction: where the two predictions are within a factor of about three of
each other (a contact set that changes often on a small zone, or seldom on a large one) the
other route may be the faster by as much; ``contact.flexibility`` chooses for the user who
knows.
"""

from __future__ import annotations

from ...memory import factor_entries

#: seconds per cube of a body's contact dofs: the dense route's condensation and W
DENSE_CUBE = 1.39e-11
#: seconds per square of a body's contact dofs: the dense route's lower-order terms
DENSE_SQUARE = 5.7e-8
#: seconds per factor entry per application of W on the matrix-free route
APPLY = 5.2e-10
#: seconds per body per application of W besides its factor's entries (the operator's own
#: arithmetic and calls)
APPLY_FIXED = 3e-4
#: applications of W a load step plans for: the geometric mean of the flat plates' 40 (one
#: contact set, two GMRES solves of 19 products) and the sphere's 308 (ten sets a step, 25-57
#: products a solve), so that neither kind of zone is mispredicted by more than their ratio
PRODUCTS_PER_STEP = 110


def predicted_seconds(surfaces, steps: int, backend: str | None = None) -> dict[str, float]:
    """The seconds each route is predicted to cost beyond what both do, ``{"dense": ...,
    "matrix_free": ...}``, for the contact ``surfaces`` over ``steps`` load steps with
    ``backend`` (see the module docstring)."""
    cube = square = entries = 0.0
    bodies = 0
    for s in surfaces:
        body = s.body
        m = float(len(s.condensed_dofs)) if s.nc else 0.0
        cube += m**3
        square += m**2
        if s.nc:  # a body with no contact surface is never applied
            entries += factor_entries(body.dim * body.npoints, 0, backend, body.dim)
            bodies += 1
    products = PRODUCTS_PER_STEP * max(steps, 1)
    return {"dense": DENSE_CUBE * cube + DENSE_SQUARE * square,
            "matrix_free": products * (APPLY * entries + APPLY_FIXED * bodies)}


__all__ = ["predicted_seconds"]
